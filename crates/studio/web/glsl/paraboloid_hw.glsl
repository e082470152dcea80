// The dual paraboloid as fixed-function hardware drew it (Heidrich & Seidel 1998; Zimmons
// 1999, "Indexing Method (matrix way)"): the two halves as two 2D textures whose texels
// outside the disk have alpha 0 (gl.js `paraboloidTextures`), both looked up, and the alpha
// choosing. Each half's texture matrix (uParaMatrix, gl.js `paraboloidTextureMatrices`)
// takes the reflected vector (r, 1) to homogeneous (s, t, -, q): with l the vector in the
// half's frame (core azimuthal.rs `DualParaboloid`: the back half's frame is the front's
// turned half a turn about up), q = 1 + l.z and (s, t) = (1/2)(q + l.x, q - l.y), so
// (s/q, t/q) is the stereographic (u, v) of paraboloid.glsl for a unit r. The divide is
// per pixel; what is divided is the vector the mode interpolates, which in modes 1 and 2 (a
// per-vertex vector interpolated across the triangle) is shorter than 1 inside a triangle:
// there the halves' disks overlap (both alphas 1 near the equator) and (s/q, t/q) is not
// the exact read. Texture unit 1 (the back) is combined over unit 0 (the front) as
// GL_DECAL: c = front (1 - alpha_back) + back alpha_back. Comes after bilinear.glsl.
uniform highp sampler2D uFront;
uniform highp sampler2D uBack;
uniform mat4 uParaMatrix[2];

// Texel (x, y) of a half's padded texture (its alpha says whether the texel's centre is in
// the disk).
vec4 paraTexel(highp sampler2D t, int x, int y) {
    ivec2 p = clamp(ivec2(x, y) + 1, ivec2(0), uEnvSize + 1);
    return texelFetch(t, p, 0);
}

// One half: its texture coordinates for r, and its bilinear RGBA there (alpha 0 where q is
// not positive: the divide has no answer).
vec4 paraHalf(highp sampler2D t, mat4 m, vec3 r) {
    vec4 stq = m * vec4(r, 1.0);
    if (!(stq.w > 0.0)) {
        return vec4(0.0);
    }
    ivec2 i;
    vec2 f = bilinearCorner(stq.xy / stq.w, uEnvSize, i);
    return bilinearMix(paraTexel(t, i.x, i.y), paraTexel(t, i.x + 1, i.y), paraTexel(t, i.x, i.y + 1), paraTexel(t, i.x + 1, i.y + 1), f);
}

// The environment along r (not necessarily unit) as the two textures and the alpha give it,
// times the intensity.
vec3 paraRead(vec3 r) {
    vec4 front = paraHalf(uFront, uParaMatrix[0], r);
    vec4 back = paraHalf(uBack, uParaMatrix[1], r);
    vec3 c = front.rgb * (1.0 - back.a) + back.rgb * back.a;
    return uIntensity == 1.0 ? c : c * uIntensity;
}
