// Greene live's Omnimax view (greene.js): the capture through an equidistant fisheye, per
// pixel: the pixel centre's (u, v) in the view at uOrigin of size uSize (v = 0 at the top,
// as a map's rows), its direction by fisheyeDir (greene-fisheye-inverse.glsl, before this
// file with math.glsl and display.glsl), the cube looked up along it. Outside the disk: empty,
// (0, 0, 0, 0). DIRS 1: the direction itself, alpha 1 in the disk (the test's, against the
// core's `uv_to_dir`).
uniform highp samplerCube uCube;
uniform vec2 uOrigin;
uniform vec2 uSize;

out vec4 outColor;

void main() {
    vec2 q = (gl_FragCoord.xy - uOrigin) / uSize;
    vec3 d = fisheyeDir(vec2(q.x, 1.0 - q.y));
    if (!(dot(d, d) > 0.0)) {
        outColor = vec4(0.0);
        return;
    }
#if DIRS
    outColor = vec4(d, 1.0);
#else
    outColor = vec4(display(texture(uCube, d).rgb), 1.0);
#endif
}
