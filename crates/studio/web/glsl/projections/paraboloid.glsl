// needs: radial lens
// Dual paraboloid: direction -> (u, v, layer), as mirrorball-core's projection/azimuthal.rs
// (`DualParaboloid`): layer 0 when forward.d >= 0 (uFrame's third column is forward), else
// layer 1, whose frame is layer 0's turned half a turn about up (right -> -right, forward ->
// -forward); in each a stereographic lens, rho = tan(theta/2) (theta_max = pi/2, tan(pi/4)
// = 1). Comes after radial.glsl and lens.glsl.
float lensRho(float s, float z, float len) {
    return lensStereographic(s, z, len);
}

vec3 envUv(vec3 d) {
    if (!(dot(d, d) > 0.0)) {
        return MB_NONE;
    }
    vec3 l = transpose(uFrame) * d;
    float layer = l.z >= 0.0 ? 0.0 : 1.0;
    if (layer == 1.0) {
        l = vec3(-l.x, l.y, -l.z);
    }
    return vec3(radialUv(l), layer);
}
