// The viewport's fragment stage (prepended as viewport.vert, then bilinear.glsl,
// display.glsl, interpolate.glsl and cone.glsl): the mode's reflected direction, as
// mirrorball-render's render/shade.rs (`Prepared::shade`, `env_color`), render/texgen.rs
// (`texgen_read`) and render/cone.rs (mode 4: the pixel's cone), read through the
// projection's envUv, shown as display.glsl says. The background is the camera's rays
// (render/background.rs, camera.rs `Rays::ray`), in mode 4 filtered over the cone of the
// pixel's corner rays as the CPU filters it. CONE_READ (gl.js `coneRead`) is cone.glsl's
// coneRead (the CPU's trilinear) or coneReadAnisotropic (in the place of its EWA). With
// PARA_HW defined (a dual paraboloid drawn as the hardware did, modes 1-3),
// paraboloid_hw.glsl comes after cone.glsl and its paraRead reads instead of envRead.
// MATERIAL (gl.js; 0 when not defined, as the simulator's passes compile it) picks the
// objects' material: 0 the mirror, indexed by the mode; 1 the prefiltered GGX chain in
// the per-pixel reflected direction, 2 the Lambert SH9 at the per-pixel normal
// (lighting.glsl, included before this file for 1 and 2): the prefiltered materials are
// shaded per pixel whatever the mode.
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

uniform vec3 uTint;

out vec4 outColor;

// The environment along unit d; with PARA_HW (paraboloid_hw.glsl), as the two textures give it.
vec3 lookup(vec3 d) {
#ifdef PARA_HW
    return paraRead(d);
#else
    return envRead(envUv(d));
#endif
}

void main() {
#if BACKGROUND
    vec3 o;
    vec3 dir;
    cameraRay(gl_FragCoord.xy, o, dir);
#if MODE == 4
    vec3 corners[4];
    for (int k = 0; k < 4; k++) {
        cameraRay(gl_FragCoord.xy + MB_CORNERS[k], o, corners[k]);
        corners[k] = attach(corners[k]);
    }
    outColor = vec4(display(CONE_READ(attach(dir), corners)), 1.0);
#else
    outColor = vec4(display(lookup(attach(dir))), 1.0);
#endif
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
#elif MODE == 4
    vec3 n = normalizeOrZero(vNrm);
    vec3 v = uPersp ? normalizeOrZero(vPos - uEye) : uForward;
    vec3 corners[4];
    for (int k = 0; k < 4; k++) {
        corners[k] = attach(cornerReflection(k, vP0, vP1, vP2, vN0, vN1, vN2, n));
    }
    c = CONE_READ(attach(v - 2.0 * dot(n, v) * n), corners);
#elif MODE == 3
    vec3 n = normalizeOrZero(vNrm);
    vec3 v = uPersp ? normalizeOrZero(vPos - uEye) : uForward;
    c = lookup(attach(v - 2.0 * dot(n, v) * n));
#elif MODE == 2
#ifdef PARA_HW
    // The hardware divides the interpolated vector as it is (paraboloid_hw.glsl).
    c = paraRead(uAttachEye ? mat3(uView) * vR : vR);
#else
    c = lookup(attach(normalizeOrZero(vR)));
#endif
#else
#if defined(PARA_HW) && TEXGEN == 1
    c = paraRead(vR);
#elif TEXGEN == 1
    c = lookup(normalizeOrZero(vR));
#else
    c = envRead(vec3(vR.xy, 0.0));
#endif
#endif
    outColor = vec4(display(c * uTint), 1.0);
#endif
}
