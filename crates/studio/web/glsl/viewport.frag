// The viewport's fragment stage (prepended as viewport.vert, then bilinear.glsl,
// display.glsl and interpolate.glsl): the mode's reflected direction, as mirrorball-render's render/shade.rs
// (`Prepared::shade`, `env_color`) and render/texgen.rs (`texgen_read`), read through the
// projection's envUv, shown as display.glsl says. The background is the camera's rays
// (render/background.rs, camera.rs `Rays::ray`). MATERIAL (gl.js; 0 when not defined, as
// the simulator's passes compile it) picks the objects' material: 0 the mirror, indexed by
// the mode; 1 the prefiltered GGX chain in the per-pixel reflected direction, 2 the Lambert
// SH9 at the per-pixel normal (lighting.glsl, included before this file for 1 and 2): the
// prefiltered materials are shaded per pixel whatever the mode.
#ifndef MATERIAL
#define MATERIAL 0
#endif
flat in vec4 vClip0;
flat in vec4 vClip1;
flat in vec4 vClip2;
flat in vec3 vP0;
flat in vec3 vP1;
flat in vec3 vP2;
flat in vec3 vN0;
flat in vec3 vN1;
flat in vec3 vN2;
flat in vec3 vC0;
flat in vec3 vC1;
flat in vec3 vC2;

uniform mat4 uView;
uniform vec3 uEye;
uniform bool uPersp;
uniform vec3 uForward;
uniform bool uAttachEye;
uniform vec3 uTint;
// The background's rays: right and up scaled by the lens (tan(fov/2)·aspect, tan(fov/2)),
// and the viewport's size in pixels.
uniform vec3 uRayRight;
uniform vec3 uRayUp;

out vec4 outColor;

vec3 normalizeOrZero(vec3 v) {
    float l = length(v);
    return l > 0.0 ? v / l : vec3(0.0);
}

// World direction r to the environment's direction (`Prepared::attach32`).
vec3 attach(vec3 r) {
    return normalizeOrZero(uAttachEye ? mat3(uView) * r : r);
}

vec3 lookup(vec3 d) {
    return envRead(envUv(d));
}

void main() {
#if BACKGROUND
    vec2 ndc = 2.0 * gl_FragCoord.xy / uViewportSize - 1.0;
    vec3 dir = uPersp ? normalizeOrZero(uForward + uRayRight * ndc.x + uRayUp * ndc.y) : uForward;
    outColor = vec4(display(lookup(attach(dir))), 1.0);
#else
    vec3 b = cornerWeights(vClip0, vClip1, vClip2);
    vec3 vPos = b.x * vP0 + b.y * vP1 + b.z * vP2;
    vec3 vNrm = b.x * vN0 + b.y * vN1 + b.z * vN2;
    vec3 vR = b.x * vC0 + b.y * vC1 + b.z * vC2;
    vec3 c;
#if MATERIAL == 1
    vec3 n = normalizeOrZero(vNrm);
    vec3 v = uPersp ? normalizeOrZero(vPos - uEye) : uForward;
    c = chainRead(attach(v - 2.0 * dot(n, v) * n));
#elif MATERIAL == 2
    c = irradiance(attach(normalizeOrZero(vNrm)));
#elif MODE == 3
    vec3 n = normalizeOrZero(vNrm);
    vec3 v = uPersp ? normalizeOrZero(vPos - uEye) : uForward;
    c = lookup(attach(v - 2.0 * dot(n, v) * n));
#elif MODE == 2
    c = lookup(attach(normalizeOrZero(vR)));
#else
#if TEXGEN == 1
    c = lookup(normalizeOrZero(vR));
#else
    c = envRead(vec3(vR.xy, 0.0));
#endif
#endif
    outColor = vec4(display(c * uTint), 1.0);
#endif
}
