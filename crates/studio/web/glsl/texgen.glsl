// GL_SPHERE_MAP's texture coordinates for an eye-space reflection vector r, verbatim from
// the OpenGL specification (2.1, section 2.12.4; mirrorball-core's `SphereMap::gl_st`):
// m = 2 sqrt(rx^2 + ry^2 + (rz + 1)^2), s = rx/m + 1/2, t = ry/m + 1/2.
vec2 glSphereSt(vec3 r) {
    float m = 2.0 * sqrt(r.x * r.x + r.y * r.y + (r.z + 1.0) * (r.z + 1.0));
    return vec2(r.x / m + 0.5, r.y / m + 0.5);
}
