// needs: radial
// The four lenses of mirrorball-core's projection/azimuthal.rs (`Lens`, `RadialMap::rho_of_theta`
// before its division by k): f(theta) for a direction at s = |l| sin(theta), z = |l| cos(theta),
// len = |l| (radial.glsl), each written so that it stays well-conditioned where it is used.
// Comes after radial.glsl.

// Equidistant: theta itself.
float lensEquidistant(float s, float z, float len) {
    return mbAtan2(s, z);
}

// Equisolid: sin(theta/2) = sqrt((1 - cos theta)/2) towards the back (z < 0), and
// = sin(theta)/sqrt(2(1 + cos theta)) towards the front (z >= 0), so that neither subtracts
// nearly equal numbers.
float lensEquisolid(float s, float z, float len) {
    return z < 0.0 ? sqrt((len - z) / (2.0 * len)) : s / sqrt(2.0 * len * (len + z));
}

// Stereographic: tan(theta/2) = sin(theta)/(1 + cos theta) (Heidrich & Seidel's
// (x, y)/(1 + z) for the paraboloid).
float lensStereographic(float s, float z, float len) {
    return s / (len + z);
}

// Orthographic: sin(theta) (theta <= pi/2).
float lensOrthographic(float s, float z, float len) {
    return s / len;
}
