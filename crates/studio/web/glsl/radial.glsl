// The disk maps' one machine, as mirrorball-core's projection/azimuthal.rs (`RadialMap`,
// `dir_to_ab`, `ab_to_uv`): a direction at angle theta from the frame's axis lands at radius
// rho(theta) of the unit disk, in the direction of its azimuth; a = 2u - 1 to the right,
// b = 1 - 2v upwards. Comes after math.glsl (uFrame) and before lens.glsl and the map's own
// file, which defines lensRho and envUv.
//
// The lens is given theta as s = |l| sin(theta), z = |l| cos(theta) and |l| rather than as an
// angle: each map writes rho by an identity that is well-conditioned where it is used,
// without sin or tan, whose GPU versions (SwiftShader's among them) are approximations that
// were off by up to 2e-4 in rho here (the equidistant lens's angle is math.glsl's atan).

// The lens: rho for a direction at (s, z) in the plane through the axis, |l| = len.
float lensRho(float s, float z, float len);

// (u, v) of `local` = (right.d, up.d, axis.d).
vec2 radialUv(vec3 local) {
    float s = sqrt(local.x * local.x + local.y * local.y);
    float len = length(local);
    float rho = lensRho(s, local.z, len);
    vec2 ab = s > 0.0 ? local.xy * (rho / s) : vec2(rho, 0.0);
    return vec2(0.5 * (ab.x + 1.0), 0.5 * (1.0 - ab.y));
}
