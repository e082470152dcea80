// needs: radial lens
// OpenGL sphere map: direction -> (u, v, layer), as mirrorball-core's projection/azimuthal.rs
// (`SphereMap`): an equal-area lens, rho = sin(theta/2) (theta_max = pi, so sin(theta_max/2)
// = 1), theta measured from the axis pointing back at the camera that took it (uFrame's third
// column is -forward); every direction is covered. Comes after radial.glsl and lens.glsl.
float lensRho(float s, float z, float len) {
    return lensEquisolid(s, z, len);
}

vec3 envUv(vec3 d) {
    if (!(dot(d, d) > 0.0)) {
        return MB_NONE;
    }
    return vec3(radialUv(transpose(uFrame) * d), 0.0);
}
