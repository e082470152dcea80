// Sinusoidal (Sanson–Flamsteed): direction -> (u, v, layer), as mirrorball-core's
// projection/pseudo.rs (`Sinusoidal::dir_to_uv`): a = lambda cos(phi)/pi, b = phi/(pi/2),
// (u, v) = ((a + 1)/2, (1 - b)/2), cos phi = sqrt(x^2 + z^2) for |d| = 1. Comes after math.glsl.
vec3 envUv(vec3 d) {
    float len = length(d);
    if (!(len > 0.0)) {
        return MB_NONE;
    }
    vec3 n = d / len;
    float a = mbLongitude(n) * sqrt(n.x * n.x + n.z * n.z) / MB_PI;
    float b = mbLatitude(n) / MB_HALF_PI;
    return vec3(0.5 * (a + 1.0), 0.5 * (1.0 - b), 0.0);
}
