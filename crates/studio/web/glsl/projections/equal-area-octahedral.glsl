// Clarberg's equal-area octahedral map: direction -> (u, v, layer), as mirrorball-core's
// projection/octahedral.rs (`EqualAreaOctahedral::dir_to_uv`, which cites the paper):
// r = sqrt(1 - |y|) written sqrt((x^2 + z^2)/(1 + |y|)) for |d| = 1 (no cancellation near the
// poles), phi = atan2(|z|, |x|), |b| = r phi/(pi/2), |a| = r - |b|, folded for y < 0 to
// (1 - |b|, 1 - |a|), the signs of x and z; (u, v) = ((a + 1)/2, (b + 1)/2). Comes after
// math.glsl.
vec3 envUv(vec3 d) {
    float hz2 = d.x * d.x + d.z * d.z;
    float len2 = hz2 + d.y * d.y;
    if (!(len2 > 0.0) || isinf(len2)) {
        return MB_NONE;
    }
    float r = sqrt(hz2 / (len2 + abs(d.y) * sqrt(len2)));
    float phi = mbAtan2(abs(d.z), abs(d.x));
    float bb = r * phi / MB_HALF_PI;
    float aa = r - bb;
    vec2 ab = d.y >= 0.0 ? vec2(aa, bb) : vec2(1.0 - bb, 1.0 - aa);
    ab *= vec2(mbSign(d.x), mbSign(d.z));
    return vec3(0.5 * (ab + 1.0), 0.0);
}
