// needs: cubeface
// OpenGL cube map: direction -> (u, v, layer), as mirrorball-core's `CubeMap::uv_f32`: the
// face of cubeface.glsl, s = sc/(2|ma|) + 1/2, t = tc/(2|ma|) + 1/2, row 0 at t = 0. Layer -1:
// no face (a zero or non-finite direction). Comes after cubeface.glsl.
vec3 envUv(vec3 d) {
    vec4 f = cubeFace(d);
    if (!(f.z > 0.0)) {
        return MB_NONE;
    }
    float k = 0.5 / f.z;
    return vec3(f.x * k + 0.5, f.y * k + 0.5, f.w);
}
