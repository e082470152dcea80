// Greene live's mirror sphere (greene.js), drawn over its bounding box: each pixel's ray
// from uEye through the box meets the sphere (centre uCentre, radius uRadius) exactly or
// the pixel is discarded; the ray reflected about the sphere's normal there is looked up
// in the capture (the samplerCube: the GL cube map's own face selection), times uTint, with
// the hit's depth. Greene's approximation: the capture is the world seen from the centre,
// so the reflected ray's direction alone chooses the texel (no parallax).
// CAPTURE 1 is only the test's negative control (greene.js `selfVisible`): the sphere drawn
// into its own capture, as the marker colour uTint with alpha uMarker.
uniform vec3 uTint;
uniform float uMarker;
#if !CAPTURE
uniform highp samplerCube uCube;
uniform vec3 uEye;
uniform vec3 uCentre;
uniform float uRadius;
uniform mat4 uViewProj;
#endif

in vec3 vWorld;
in vec3 vNormal;

out vec4 outColor;

void main() {
#if CAPTURE
    outColor = vec4(uTint, uMarker);
#else
    vec3 d = normalize(vWorld - uEye);
    vec3 o = uEye - uCentre;
    float b = dot(o, d);
    float disc = b * b - (dot(o, o) - uRadius * uRadius);
    if (disc < 0.0) {
        discard;
    }
    vec3 p = uEye + (-b - sqrt(disc)) * d;
    vec3 n = (p - uCentre) / uRadius;
    vec3 r = d - 2.0 * dot(n, d) * n;
    vec4 clip = uViewProj * vec4(p, 1.0);
    gl_FragDepth = 0.5 * clip.z / clip.w + 0.5;
    outColor = vec4(display(texture(uCube, r).rgb * uTint), 1.0);
#endif
}
