// Greene live's moving objects (greene.js): a flat colour, uColour (linear radiance) times
// 0.55 + 0.45 max(n.uLight, 0), a scalar, so the colour's chromaticity is uColour's
// everywhere. CAPTURE 1: linear radiance, alpha uMarker (2 + the object's index: the test
// tells the objects and the background, alpha 1, apart in the capture); CAPTURE 0: displayed
// (display.glsl comes before).
uniform vec3 uColour;
uniform vec3 uLight;
uniform float uMarker;

in vec3 vWorld;
in vec3 vNormal;

out vec4 outColor;

void main() {
    vec3 n = normalize(vNormal);
    vec3 c = uColour * (0.55 + 0.45 * max(dot(n, uLight), 0.0));
#if CAPTURE
    outColor = vec4(c, uMarker);
#else
    outColor = vec4(display(c), 1.0);
#endif
}
