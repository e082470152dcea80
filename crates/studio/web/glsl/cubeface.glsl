// OpenGL cube map face selection, as mirrorball-core's projection/cube.rs (`major_face`,
// `face_coords`; OpenGL 4.6 section 8.13, table 8.19): the major axis picks the face (ties to
// x, then y; a component >= 0, -0.0 included, picks the positive face), faces +X -X +Y -Y +Z
// -Z as layers 0..5. Returns (sc, tc, |ma|, layer); the cube and the continuous cube read it.
vec4 cubeFace(vec3 d) {
    vec3 a = abs(d);
    if (a.x >= a.y && a.x >= a.z) {
        return d.x >= 0.0 ? vec4(-d.z, -d.y, a.x, 0.0) : vec4(d.z, -d.y, a.x, 1.0);
    } else if (a.y >= a.z) {
        return d.y >= 0.0 ? vec4(d.x, d.z, a.y, 2.0) : vec4(d.x, -d.z, a.y, 3.0);
    }
    return d.z >= 0.0 ? vec4(d.x, -d.y, a.z, 4.0) : vec4(-d.x, -d.y, a.z, 5.0);
}
