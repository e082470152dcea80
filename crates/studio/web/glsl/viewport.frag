// The viewport's fragment stage (prepended as viewport.vert, then bilinear.glsl,
// display.glsl, interpolate.glsl and cone.glsl): the mode's reflected direction, as
// mirrorball-render's render/shade.rs (`Prepared::shade`, `env_color`), render/texgen.rs
// (`texgen_read`) and render/cone.rs (mode 4: the pixel's cone), read through the
// projection's envUv, shown as display.glsl says. The background is the camera's rays
// (render/background.rs, camera.rs `Rays::ray`), in mode 4 filtered over the cone of the
// pixel's corner rays as the CPU filters it, or blurred along the path it swept since the
// previous frame (`sweep`, a panning camera). CONE_READ (gl.js `coneRead`) is cone.glsl's
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

#if BACKGROUND && defined(PAN_BLUR)
// Camera-rotation motion blur (Greene §9; render/blur.rs `sweep`, `Settings::motion_from`):
// the previous frame's camera is this one panned by the page's angle (camera.rs
// `Camera::panned`), its rays uPrevForward + uPrevRayRight x + uPrevRayUp y as cameraRay's.
// Compiled in only with PAN_BLUR (gl.js `viewportProgram`'s `panBlur`).
uniform vec3 uPrevForward;
uniform vec3 uPrevRayRight;
uniform vec3 uPrevRayUp;

// The previous frame's camera ray through window position w, as cameraRay.
vec3 prevCameraRay(vec2 w) {
    vec2 ndc = 2.0 * w / uViewportSize - 1.0;
    return uPersp ? normalizeOrZero(uPrevForward + uPrevRayRight * ndc.x + uPrevRayUp * ndc.y) : uPrevForward;
}

// Spherical interpolation from unit a to unit b, `angle` apart, at t (blur.rs `slerp`).
vec3 slerp(vec3 a, vec3 b, float angle, float t) {
    if (angle < 1e-9) {
        return a;
    }
    float s = sin(angle);
    if (abs(s) < 1e-9) {
        return normalizeOrZero(a * (1.0 - t) + b * t);
    }
    return normalizeOrZero(a * (sin((1.0 - t) * angle) / s) + b * (sin(t * angle) / s));
}

// The path from d0 to d1 (attached, unit), sampled about once per texel along its length
// (at most 64 samples) and averaged. The texel's angular size at d1 is the square root of
// its solid angle, 1 / sqrt(W H |det J|), J = d(u, v)/d(t1, t2) found by envUv's central
// differences (cone.glsl `uvAlong`): the CPU's density_of_dir / (W H), whose square root it
// takes. Where J is not found (a step leaves the layer), 64 samples.
vec3 sweep(vec3 d0, vec3 d1) {
    float angle = mbAtan2(length(cross(d0, d1)), dot(d0, d1));
    vec3 at = envUv(d1);
    vec3 t1 = vec3(d1.z, 0.0, -d1.x);
    t1 = dot(t1, t1) > 1e-20 ? normalize(t1) : vec3(1.0, 0.0, 0.0);
    vec3 t2 = cross(d1, t1);
    vec2 j1;
    vec2 j2;
    int n = 64;
    if (at.z >= 0.0 && uvAlong(d1, t1, at, j1) && uvAlong(d1, t2, at, j2)) {
        float det = abs(j1.x * j2.y - j1.y * j2.x);
        float texel = max(1.0 / sqrt(float(uEnvSize.x) * float(uEnvSize.y) * det), 1e-9);
        n = int(clamp(ceil(angle / texel), 1.0, 64.0));
    }
    vec3 acc = vec3(0.0);
    for (int k = 0; k < 64; k++) {
        if (k >= n) {
            break;
        }
        acc += lookup(slerp(d0, d1, angle, (float(k) + 0.5) / float(n)));
    }
    return acc / float(n);
}
#endif

void main() {
#if BACKGROUND
    vec3 o;
    vec3 dir;
    cameraRay(gl_FragCoord.xy, o, dir);
#if defined(PAN_BLUR)
    outColor = vec4(display(sweep(attach(prevCameraRay(gl_FragCoord.xy)), attach(dir))), 1.0);
#elif MODE == 4
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
