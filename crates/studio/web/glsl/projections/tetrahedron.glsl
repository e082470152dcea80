// FFmpeg v360's tetrahedron: direction -> (u, v, layer), as mirrorball-core's
// projection/tetrahedron.rs (`Tetrahedron::dir_to_uv`): m = the largest n.d over the faces'
// normals, the left half's (1, -1, 1), (-1, 1, 1) giving z + |x - y| and the right half's
// (1, 1, -1), (-1, -1, -1) giving -z + |x + y|; the point p = d/m on the tetrahedron;
// u = (p.x + 1)/4 on the left half, (3 - p.x)/4 on the right, v = (1 + p.y)/2 (the top of the
// picture looks down, as in v360). Scale-invariant. Comes after math.glsl.
vec3 envUv(vec3 d) {
    float left = d.z + abs(d.x - d.y);
    float right = -d.z + abs(d.x + d.y);
    float m = max(left, right);
    if (!(m > 0.0) || isinf(m)) {
        return MB_NONE;
    }
    vec3 p = d / m;
    float u = left >= right ? 0.25 * (p.x + 1.0) : 0.25 * (3.0 - p.x);
    return vec3(u, 0.5 * (1.0 + p.y), 0.0);
}
