// The views (perspective, Pannini): direction -> (u, v, layer), as mirrorball-core's
// projection/perspective.rs (`View::dir_to_uv`, `plane_of_local`): in the view's frame
// (uFrame: right, up, forward) l = (x, y, z), h = sqrt(x^2 + z^2), the picture plane
// (X, Y) = (x, y)(d + 1)/(d h + z), (a, b) = (X/X_max, Y/Y_max), (u, v) = ((a + 1)/2, (1 - b)/2);
// rectilinear is d = 0. Not covered where d h + z <= 0, z < h cos(hfov/2), or |a|, |b| > 1
// (margins of 1e-6 and 1e-5 for the f32 direction, clamped). uParams = (d, 1/X_max, 1/Y_max,
// cos(hfov/2)). Comes after math.glsl.
vec3 envUv(vec3 dir) {
    float len = length(dir);
    if (!(len > 0.0)) {
        return MB_NONE;
    }
    vec3 l = transpose(uFrame) * (dir / len);
    float h = sqrt(l.x * l.x + l.z * l.z);
    float den = uParams.x * h + l.z;
    if (!(den > 0.0) || l.z < h * uParams.w - 1e-6) {
        return MB_NONE;
    }
    vec2 ab = l.xy * ((uParams.x + 1.0) / den) * uParams.yz;
    if (abs(ab.x) > 1.0 + 1e-5 || abs(ab.y) > 1.0 + 1e-5) {
        return MB_NONE;
    }
    ab = clamp(ab, -1.0, 1.0);
    return vec3(0.5 * (ab.x + 1.0), 0.5 * (1.0 - ab.y), 0.0);
}
