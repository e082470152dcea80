// The bilinear read of the environment, as mirrorball-core's envmap.rs does it
// (`bilinear_corner`: x = u*w - 1/2, x0 = floor(x), fx = x - x0; `lerp4`: top = a + fx(b - a),
// bottom = c + fx(d - c), top + fy(bottom - top)), from the page's texture array whose layers
// the server padded by one texel with the core's seam rule (crates/studio/src/texture.rs), so
// that reads across a seam take the texels the core's `seam_taps` takes.
uniform highp sampler2DArray uEnv;
// The layers' size without the padding.
uniform ivec2 uEnvSize;
uniform float uIntensity;

vec3 envTexel(int layer, int x, int y) {
    ivec2 p = clamp(ivec2(x, y) + 1, ivec2(0), uEnvSize + 1);
    return texelFetch(uEnv, ivec3(p, layer), 0).rgb;
}

// The environment at (u, v, layer); black where layer < 0 or u, v are not finite (the CPU's
// `read_uv32`), times the environment's intensity.
vec3 envRead(vec3 uvl) {
    if (uvl.z < 0.0 || isnan(uvl.x) || isnan(uvl.y) || isinf(uvl.x) || isinf(uvl.y)) {
        return vec3(0.0);
    }
    float x = uvl.x * float(uEnvSize.x) - 0.5;
    float y = uvl.y * float(uEnvSize.y) - 0.5;
    float x0 = floor(x);
    float y0 = floor(y);
    float fx = x - x0;
    float fy = y - y0;
    int l = int(uvl.z);
    int i = int(x0);
    int j = int(y0);
    vec3 a = envTexel(l, i, j);
    vec3 b = envTexel(l, i + 1, j);
    vec3 c = envTexel(l, i, j + 1);
    vec3 d = envTexel(l, i + 1, j + 1);
    vec3 top = a + fx * (b - a);
    vec3 bottom = c + fx * (d - c);
    vec3 e = top + fy * (bottom - top);
    return uIntensity == 1.0 ? e : e * uIntensity;
}
