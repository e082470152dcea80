// Greene live's background (greene.js): the loaded environment along each pixel's ray
// d = uForward + x uRayRight + y uRayUp, (x, y) the pixel centre in [-1, 1]^2 of the viewport
// at uOrigin of size uSize, read through the projection's own envUv (G.projectionSource,
// prepended with bilinear.glsl and display.glsl: one home per formula) and envRead.
// CAPTURE 1: a face of the cube capture, linear radiance with alpha 1 (uForward the face's
// major axis, uRayRight and uRayUp its sc and tc axes as OpenGL's cube-map table gives them,
// so the pixel at window (x, y) is the face's texel (s, t) = (x, y)/N); CAPTURE 0: the panel
// camera's rays (uRayRight, uRayUp scaled by the half field of view), displayed.
uniform vec3 uForward;
uniform vec3 uRayRight;
uniform vec3 uRayUp;
uniform vec2 uOrigin;
uniform vec2 uSize;

out vec4 outColor;

void main() {
    vec2 p = 2.0 * (gl_FragCoord.xy - uOrigin) / uSize - 1.0;
    vec3 d = normalize(uForward + p.x * uRayRight + p.y * uRayUp);
    vec3 c = envRead(envUv(d));
#if CAPTURE
    outColor = vec4(c, 1.0);
#else
    outColor = vec4(display(c), 1.0);
#endif
}
