// needs: cubeface
// Equi-angular cube map (YouTube's EAC, v360's eac): direction -> (u, v, layer), as
// mirrorball-core's projection/eac.rs: OpenGL's face and (s, t) axes (cubeface.glsl), and
// inside the face the angle instead of the tangent, p = 4/pi atan(sc/|ma|), likewise q,
// (u, v) = ((p + 1)/2, (q + 1)/2). The face arrangement in one picture is a layout the server
// undoes (each face is its own layer here). Comes after math.glsl and cubeface.glsl.
vec3 envUv(vec3 d) {
    vec4 f = cubeFace(d);
    if (!(f.z > 0.0)) {
        return MB_NONE;
    }
    float p = mbAtan2(f.x, f.z) / (0.5 * MB_HALF_PI);
    float q = mbAtan2(f.y, f.z) / (0.5 * MB_HALF_PI);
    return vec3(0.5 * (p + 1.0), 0.5 * (q + 1.0), f.w);
}
