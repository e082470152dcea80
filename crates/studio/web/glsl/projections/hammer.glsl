// Hammer's equal-area ellipse: direction -> (u, v, layer), as mirrorball-core's
// projection/pseudo.rs (`Hammer::dir_to_uv`; Snyder 1987, p. 231): with longitude lambda,
// latitude phi, Z = sqrt(1 + cos phi cos(lambda/2)), (a, b) = (cos phi sin(lambda/2), sin phi)/Z,
// (u, v) = ((a + 1)/2, (1 - b)/2). The half angle without trigonometry: for |d| = 1,
// h = cos phi, cos lambda = -z/h, so 1 + cos lambda = (h - z)/h and 1 - cos lambda = (h + z)/h;
// in front (z <= 0) cos(lambda/2) = sqrt((h - z)/2h) and sin(lambda/2) = x/(2h cos(lambda/2)),
// behind sin(lambda/2) = sgn(x) sqrt((h + z)/2h) and cos(lambda/2) = |x|/(2h |sin(lambda/2)|),
// each the well-conditioned one. Comes after math.glsl.
vec3 envUv(vec3 d) {
    float len = length(d);
    if (!(len > 0.0)) {
        return MB_NONE;
    }
    vec3 n = d / len;
    float h = sqrt(n.x * n.x + n.z * n.z);
    float s2 = 0.0;
    float c2 = 1.0;
    if (h > 0.0) {
        if (n.z <= 0.0) {
            c2 = sqrt((h - n.z) / (2.0 * h));
            s2 = n.x / (2.0 * h * c2);
        } else {
            s2 = mbSign(n.x) * sqrt((h + n.z) / (2.0 * h));
            c2 = abs(n.x) / (2.0 * h * abs(s2));
        }
    }
    float z = sqrt(1.0 + h * c2);
    return vec3(0.5 * (h * s2 / z + 1.0), 0.5 * (1.0 - n.y / z), 0.0);
}
