// The cylinders (cylindrical, cylindrical-equal-area, half-equirect): direction ->
// (u, v, layer), as mirrorball-core's projection/cylindrical.rs (`Cylinder::dir_to_uv`,
// `b_of_dir`): a = longitude·2/H, b = g(latitude)/g(V/2) with g = tan (central: y/h),
// sin (equal-area: y) or the identity (equidistant: atan2(y, h)), h = sqrt(x^2 + z^2), |d| = 1;
// (u, v) = ((a + 1)/2, (1 - b)/2). Not covered where |a| or |b| > 1, with a margin of 1e-5
// for the f32 direction, clamped. uParams = (rule: 0 central, 1 equal-area, 2 equidistant;
// 2/H; 1/g(V/2)). Comes after math.glsl.
vec3 envUv(vec3 d) {
    float len = length(d);
    if (!(len > 0.0)) {
        return MB_NONE;
    }
    vec3 n = d / len;
    float h = sqrt(n.x * n.x + n.z * n.z);
    float a = mbLongitude(n) * uParams.y;
    int rule = int(uParams.x);
    float g;
    if (rule == 0) {
        if (!(h > 0.0)) {
            return MB_NONE;
        }
        g = n.y / h;
    } else if (rule == 1) {
        g = n.y;
    } else {
        g = mbAtan2(n.y, h);
    }
    float b = g * uParams.z;
    if (abs(a) > 1.0 + 1e-5 || abs(b) > 1.0 + 1e-5) {
        return MB_NONE;
    }
    a = clamp(a, -1.0, 1.0);
    b = clamp(b, -1.0, 1.0);
    return vec3(0.5 * (a + 1.0), 0.5 * (1.0 - b), 0.0);
}
