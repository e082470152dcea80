// The fisheye's inverse, (u, v) -> direction, as mirrorball-core's projection/azimuthal.rs
// (`Fisheye`'s `uv_to_dir`: `RadialMap::uv_to_ab`, `ab_to_dir`, `ab_to_dir_of`): a = 2u - 1
// to the right, b = 1 - 2v upwards, rho = |(a, b)|; no direction (the zero vector) past the
// rim (rho > 1); theta = k rho for the equidistant lens (uParams as state.rs `params_of`
// gives a fisheye's: lens 0, k = theta_max), the only lens written here (the others give no
// direction); the direction forward cos(theta) + (right a + up b) sin(theta)/rho,
// normalised, in uFrame's columns (right, up, forward). The inverse's one home: fisheye.glsl
// is the forward map. Comes after math.glsl.
//
// sin and cos of theta in [0, pi] as Cephes' single-precision sinf and cosf (S. L. Moshier,
// cephes/single/sinf.c, cosf.c): reduced about 0, pi/2 or pi to [-pi/4, pi/4], then their
// polynomials (errors about 1e-7); not the GPU's own, approximations of unstated accuracy
// (math.glsl says the same of atan).
void mbSinCos(float x, out float s, out float c) {
    float q = floor(x / MB_HALF_PI + 0.5);
    float r = x - q * MB_HALF_PI;
    float z = r * r;
    float sr = ((-1.9515295891e-4 * z + 8.3321608736e-3) * z - 1.6666654611e-1) * z * r + r;
    float cr = ((2.443315711809948e-5 * z - 1.388731625493765e-3) * z + 4.166664568298827e-2) * z * z
        - 0.5 * z + 1.0;
    if (q < 0.5) {
        s = sr;
        c = cr;
    } else if (q < 1.5) {
        s = cr;
        c = -sr;
    } else {
        s = -sr;
        c = -cr;
    }
}

vec3 fisheyeDir(vec2 uv) {
    vec2 ab = vec2(2.0 * uv.x - 1.0, 1.0 - 2.0 * uv.y);
    float rho = length(ab);
    if (!(rho <= 1.0) || int(uParams.x) != 0) {
        return vec3(0.0);
    }
    if (rho == 0.0) {
        return uFrame[2];
    }
    float s;
    float c;
    mbSinCos(min(uParams.y * rho, MB_PI), s, c);
    return normalize(uFrame[2] * c + (uFrame[0] * ab.x + uFrame[1] * ab.y) * (s / rho));
}
