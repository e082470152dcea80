// Perspective-correct interpolation at the fragment's centre, OpenGL ES 3.0 section 3.6.1
// eq. 3.8 (OpenGL 4.6 eq. 14.9): corner k's weight is f_k/w_k over the sum of f_j/w_j, f_k
// the area of the sub-triangle opposite corner k in window coordinates; mirrorball-render's
// rasteriser (raster.rs, mirror.rs) computes the same from the corners' exact window
// positions. Done here rather than by the rasteriser's own interpolation because the
// rasteriser snaps vertices to its sub-pixel grid (SwiftShader: 4 bits, GL_SUBPIXEL_BITS),
// which moves the interpolated values by up to 1/32 pixel: on a mirror sphere, enough to
// move a sharp edge of the environment by a tenth of a texel. The rasteriser still decides
// which pixels a triangle covers.
uniform vec2 uViewportSize;

vec2 windowOf(vec4 c) {
    return (c.xy / c.w * 0.5 + 0.5) * uViewportSize;
}

float cross2(vec2 a, vec2 b) {
    return a.x * b.y - a.y * b.x;
}

// The weights of the corners with clip coordinates c0, c1, c2 at the fragment's centre.
vec3 cornerWeights(vec4 c0, vec4 c1, vec4 c2) {
    vec2 p = gl_FragCoord.xy;
    vec2 s0 = windowOf(c0) - p;
    vec2 s1 = windowOf(c1) - p;
    vec2 s2 = windowOf(c2) - p;
    vec3 b = vec3(cross2(s1, s2) / c0.w, cross2(s2, s0) / c1.w, cross2(s0, s1) / c2.w);
    return b / (b.x + b.y + b.z);
}
