// needs: radial lens
// Fisheye and angular maps: direction -> (u, v, layer), as mirrorball-core's
// projection/azimuthal.rs (`Fisheye`, `AngularMap`: a `RadialMap` of any lens, `dir_to_ab`):
// rho = f(theta)/k, k = f(theta_max), theta from uFrame's third column (the map's look).
// Not covered beyond theta_max: z < |l| cos(theta_max), with a margin of 1e-6 |l| for the
// f32 direction (past the rim by that much, rho stays within 1e-5 of 1).
// uParams = (lens: 0 equidistant, 1 equisolid, 2 stereographic, 3 orthographic; k;
// cos theta_max). Angular is the equidistant lens with theta_max = pi. Comes after
// radial.glsl and lens.glsl.
float lensRho(float s, float z, float len) {
    int lens = int(uParams.x);
    float f;
    if (lens == 0) {
        f = lensEquidistant(s, z, len);
    } else if (lens == 1) {
        f = lensEquisolid(s, z, len);
    } else if (lens == 2) {
        f = lensStereographic(s, z, len);
    } else {
        f = lensOrthographic(s, z, len);
    }
    return f / uParams.y;
}

vec3 envUv(vec3 d) {
    if (!(dot(d, d) > 0.0)) {
        return MB_NONE;
    }
    vec3 l = transpose(uFrame) * d;
    float len = length(l);
    if (l.z < len * (uParams.z - 1e-6)) {
        return MB_NONE;
    }
    return vec3(radialUv(l), 0.0);
}
