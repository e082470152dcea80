// Dual paraboloid: direction -> (u, v, layer), as mirrorball-core's projection/azimuthal.rs
// (`DualParaboloid`): layer 0 when forward.d >= 0 (uFrame's third column is forward), else
// layer 1, whose frame is layer 0's turned half a turn about up (right -> -right, forward ->
// -forward); in each a stereographic lens, rho = tan(theta/2) (theta_max = pi/2, tan(pi/4)
// = 1): Heidrich & Seidel's (x, y)/(1 + z). Comes after radial.glsl.
float lensRho(float theta) {
    return tan(0.5 * theta);
}

vec3 envUv(vec3 d) {
    vec3 l = transpose(uFrame) * d;
    float layer = l.z >= 0.0 ? 0.0 : 1.0;
    if (layer == 1.0) {
        l = vec3(-l.x, l.y, -l.z);
    }
    bool ok;
    vec2 uv = radialUv(l, 0.5 * MB_PI, ok);
    return ok ? vec3(uv, layer) : vec3(0.0, 0.0, -1.0);
}
