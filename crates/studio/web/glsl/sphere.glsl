// OpenGL sphere map: direction -> (u, v, layer), as mirrorball-core's projection/azimuthal.rs
// (`SphereMap`): an equal-area lens, rho = sin(theta/2) (theta_max = pi, so sin(theta_max/2)
// = 1), theta measured from the axis pointing back at the camera that took it (uFrame's third
// column is -forward); every direction is covered. Comes after radial.glsl.
//
// sin(theta/2) = sqrt((1 - cos theta)/2) towards the rim (z < 0), and
// = sin(theta)/sqrt(2(1 + cos theta)) towards the centre (z >= 0), so that neither subtracts
// nearly equal numbers.
float lensRho(float s, float z, float len) {
    return z < 0.0 ? sqrt((len - z) / (2.0 * len)) : s / sqrt(2.0 * len * (len + z));
}

vec3 envUv(vec3 d) {
    if (!(dot(d, d) > 0.0)) {
        return vec3(0.0, 0.0, -1.0);
    }
    return vec3(radialUv(transpose(uFrame) * d), 0.0);
}
