// Octahedral: direction -> (u, v, layer), as mirrorball-core's projection/octahedral.rs
// (`Octahedral::dir_to_uv`): (a, b) = (x, z)/|d|_1 on the upper half (y >= 0), folded into the
// corners below, ((1 - |b|) sgn a, (1 - |a|) sgn b); (u, v) = ((a + 1)/2, (b + 1)/2).
// Comes after math.glsl.
vec3 envUv(vec3 d) {
    float l1 = abs(d.x) + abs(d.y) + abs(d.z);
    if (!(l1 > 0.0) || isinf(l1)) {
        return MB_NONE;
    }
    float a = d.x / l1;
    float b = d.z / l1;
    vec2 ab = d.y >= 0.0 ? vec2(a, b) : vec2((1.0 - abs(b)) * mbSign(a), (1.0 - abs(a)) * mbSign(b));
    return vec3(0.5 * (ab + 1.0), 0.0);
}
