// needs: cubeface
// Grimm & Niebruegge's continuous cube (Continuous Cube Mapping, Appendix A's Cg shader),
// corrected as mirrorball-core's projection/continuous_cube.rs corrects it (its module comment
// derives the formulas): OpenGL's face (cubeface.glsl) and (s, t) axes, and inside the face,
// with A = sc/|ma|, B = tc/|ma| and r = sqrt(1 + A^2),
//   p = atan(A/sqrt 2)/c, c = asin(1/sqrt 3)     (the shader's S1/S2: atan2(x/y, sqrt 2)),
//   q = atan(B/r)/atan(1/r)                       (the shader's asin(z)/asin(1/sqrt(2 + (x/y)^2)):
//                                                  asin z = atan(B/r), asin(1/sqrt(2 + A^2)) = atan(1/r)),
//   (u, v) = ((p + 1)/2, (q + 1)/2).
// The shader's own face rotation (each face turned to +Y) and texture order are not used:
// OpenGL's order keeps every cube layout. Comes after math.glsl and cubeface.glsl.
const float MB_CCUBE_C = 0.6154797086703873;

vec3 envUv(vec3 d) {
    vec4 f = cubeFace(d);
    if (!(f.z > 0.0)) {
        return MB_NONE;
    }
    float a = f.x / f.z;
    float b = f.y / f.z;
    float r = sqrt(1.0 + a * a);
    float p = mbAtan2(a, 1.4142135623730951) / MB_CCUBE_C;
    float q = mbAtan2(b, r) / mbAtan2(1.0, r);
    return vec3(0.5 * (p + 1.0), 0.5 * (q + 1.0), f.w);
}
