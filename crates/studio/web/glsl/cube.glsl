// OpenGL cube map: direction -> (u, v, layer), as mirrorball-core's projection/cube.rs
// (`major_face`, `face_coords`, `CubeMap::uv_f32`; OpenGL 4.6 section 8.13, table 8.19): the
// major axis picks the face (ties to x, then y; a component >= 0, -0.0 included, picks the
// positive face), s = sc/(2|ma|) + 1/2, t = tc/(2|ma|) + 1/2, faces +X -X +Y -Y +Z -Z as
// layers 0..5, row 0 at t = 0. Layer -1: no face (a zero or non-finite direction).
vec3 envUv(vec3 d) {
    vec3 a = abs(d);
    float layer;
    float sc;
    float tc;
    float ma;
    if (a.x >= a.y && a.x >= a.z) {
        ma = a.x;
        if (d.x >= 0.0) { layer = 0.0; sc = -d.z; tc = -d.y; }
        else { layer = 1.0; sc = d.z; tc = -d.y; }
    } else if (a.y >= a.z) {
        ma = a.y;
        if (d.y >= 0.0) { layer = 2.0; sc = d.x; tc = d.z; }
        else { layer = 3.0; sc = d.x; tc = -d.z; }
    } else {
        ma = a.z;
        if (d.z >= 0.0) { layer = 4.0; sc = d.x; tc = -d.y; }
        else { layer = 5.0; sc = -d.x; tc = -d.y; }
    }
    if (!(ma > 0.0)) {
        return vec3(0.0, 0.0, -1.0);
    }
    float k = 0.5 / ma;
    return vec3(sc * k + 0.5, tc * k + 0.5, layer);
}
