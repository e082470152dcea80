// The viewport's fragment stage (prepended as viewport.vert, then bilinear.glsl and
// display.glsl): the mode's reflected direction, as mirrorball-render's render/shade.rs
// (`Prepared::shade`, `env_color`) and render/texgen.rs (`texgen_read`), read through the
// projection's envUv, shown as display.glsl says. The background is the camera's rays
// (render/background.rs, camera.rs `Rays::ray`).
in vec3 vPos;
in vec3 vNrm;
in vec3 vR;

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
uniform vec2 uViewportSize;

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
    vec3 c;
#if MODE == 3
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
