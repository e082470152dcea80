// OpenGL sphere map: direction -> (u, v, layer), as mirrorball-core's projection/azimuthal.rs
// (`SphereMap`): an equal-area lens, rho = sin(theta/2) (theta_max = pi, so sin(theta_max/2)
// = 1), theta measured from the axis pointing back at the camera that took it (uFrame's third
// column is -forward). Comes after radial.glsl.
float lensRho(float theta) {
    return sin(0.5 * theta);
}

vec3 envUv(vec3 d) {
    bool ok;
    vec2 uv = radialUv(transpose(uFrame) * d, MB_PI, ok);
    return ok ? vec3(uv, 0.0) : vec3(0.0, 0.0, -1.0);
}
