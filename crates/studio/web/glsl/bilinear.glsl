// The bilinear read of the environment, as mirrorball-core's envmap.rs does it
// (`bilinear_corner`: x = u*w - 1/2, x0 = floor(x), fx = x - x0; `lerp4`: top = a + fx(b - a),
// bottom = c + fx(d - c), top + fy(bottom - top)), from the page's texture array whose layers
// the server padded by one texel with the core's seam rule (crates/studio/src/texture.rs), so
// that reads across a seam take the texels the core's `seam_taps` takes. With the mip chain
// (texture.rs `encode_mips`), each level is a padded block of the same atlas, and
// `envReadLevel` reads level k as the core reads that level of the filter crate's
// `MipChain`; `envTrilinear` blends two levels as its `Sampler::trilinear` does.
uniform highp sampler2DArray uEnv;
// The layers' size without the padding.
uniform ivec2 uEnvSize;
uniform float uIntensity;
// The mip chain: how many levels the atlas holds, and per level its padded block's top-left
// texel (.xy) and its size without the padding (.zw); level 0 is (0, 0, uEnvSize).
#define MB_MAX_LEVELS 16
uniform int uLevelCount;
uniform ivec4 uLevels[MB_MAX_LEVELS];

vec3 envTexelIn(ivec4 rect, int layer, int x, int y) {
    ivec2 p = clamp(ivec2(x, y) + 1, ivec2(0), rect.zw + 1);
    return texelFetch(uEnv, ivec3(p + rect.xy, layer), 0).rgb;
}

vec3 envTexel(int layer, int x, int y) {
    return envTexelIn(ivec4(0, 0, uEnvSize), layer, x, y);
}

bool envMissed(vec3 uvl) {
    return uvl.z < 0.0 || isnan(uvl.x) || isnan(uvl.y) || isinf(uvl.x) || isinf(uvl.y);
}

// The bilinear corner of (u, v) in a w x h layer: the top-left texel of the four, and the
// fractions towards the others (core `bilinear_corner`).
vec2 bilinearCorner(vec2 uv, ivec2 size, out ivec2 corner) {
    vec2 x = uv * vec2(size) - 0.5;
    vec2 x0 = floor(x);
    corner = ivec2(x0);
    return x - x0;
}

// The bilinear blend of the four texels a (top left), b (right of it), c (below it), d
// (core `bilinear_mix`).
vec4 bilinearMix(vec4 a, vec4 b, vec4 c, vec4 d, vec2 f) {
    vec4 top = a + f.x * (b - a);
    vec4 bottom = c + f.x * (d - c);
    return top + f.y * (bottom - top);
}

// The bilinear read of the level at `rect` (without the intensity).
vec3 envBilinearIn(ivec4 rect, vec3 uvl) {
    ivec2 i;
    vec2 f = bilinearCorner(uvl.xy, rect.zw, i);
    int l = int(uvl.z);
    vec4 a = vec4(envTexelIn(rect, l, i.x, i.y), 0.0);
    vec4 b = vec4(envTexelIn(rect, l, i.x + 1, i.y), 0.0);
    vec4 c = vec4(envTexelIn(rect, l, i.x, i.y + 1), 0.0);
    vec4 d = vec4(envTexelIn(rect, l, i.x + 1, i.y + 1), 0.0);
    return bilinearMix(a, b, c, d, f).rgb;
}

// The environment at (u, v, layer); black where layer < 0 or u, v are not finite (the CPU's
// `read_uv32`), times the environment's intensity.
vec3 envRead(vec3 uvl) {
    if (envMissed(uvl)) {
        return vec3(0.0);
    }
    vec3 e = envBilinearIn(ivec4(0, 0, uEnvSize), uvl);
    return uIntensity == 1.0 ? e : e * uIntensity;
}

// Level `level` of the mip chain at (u, v, layer), without the intensity.
vec3 envReadLevel(vec3 uvl, int level) {
    return envBilinearIn(uLevels[level], uvl);
}

// The mip chain at (u, v, layer) and level of detail `lod` (filter crate's
// `Sampler::trilinear`: lod clamped to the chain, the two levels about it blended by its
// fraction, a + f(b - a)), times the intensity; black where envRead is.
vec3 envTrilinear(vec3 uvl, float lod) {
    if (envMissed(uvl)) {
        return vec3(0.0);
    }
    lod = clamp(lod, 0.0, float(uLevelCount - 1));
    float l0 = floor(lod);
    float f = lod - l0;
    int k = int(l0);
    vec3 a = envReadLevel(uvl, k);
    if (f > 0.0) {
        a += f * (envReadLevel(uvl, k + 1) - a);
    }
    return uIntensity == 1.0 ? a : a * uIntensity;
}
