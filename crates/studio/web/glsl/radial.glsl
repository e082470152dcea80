// The disk maps' one machine, as mirrorball-core's projection/azimuthal.rs (`RadialMap`):
// a direction at angle theta from the frame's axis lands at radius rho(theta) of the unit
// disk, in the direction of its azimuth; a = 2u - 1 to the right, b = 1 - 2v upwards.
// Comes before the map's own file, which defines lensRho and envUv.
const float MB_PI = 3.14159265358979;

// The frame of layer 0 as columns: right, up, axis.
uniform mat3 uFrame;

// The lens: radius on the disk at angle theta from the axis.
float lensRho(float theta);

// (u, v) of `local` = (right.d, up.d, axis.d) for a lens rho = lensRho(theta) with
// theta_max `thetaMax`; ok is false past theta_max (`RadialMap::dir_to_ab`).
vec2 radialUv(vec3 local, float thetaMax, out bool ok) {
    float s = sqrt(local.x * local.x + local.y * local.y);
    float theta = atan(s, local.z);
    ok = theta <= thetaMax * (1.0 + 1e-7);
    float rho = lensRho(theta);
    vec2 ab = s > 0.0 ? local.xy * (rho / s) : vec2(rho, 0.0);
    return vec2(0.5 * (ab.x + 1.0), 0.5 * (1.0 - ab.y));
}
