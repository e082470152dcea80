// The fragment stage's camera and Greene's pixel cone (mode 4), as mirrorball-render's
// render/cone.rs and lookup.rs do them, and the cone's level of detail as the filter crate's
// `Sampler` takes it for trilinear filtering (sampler.rs `footprint_ellipse`, `semi_axes`).
// Comes after bilinear.glsl and interpolate.glsl (uViewportSize), before viewport.frag.
//
// The cone: the camera rays through the pixel's four corners, reflected off the hit
// triangle's plane extended to them, the normal interpolated there with the triangle's
// barycentric coordinates extrapolated (`corner_reflections`); their spread as ray
// differentials dd/dx = ((c1 - c0) + (c2 - c3))/2, dd/dy = ((c3 - c0) + (c2 - c1))/2, corners
// in the order (-,-) (+,-) (+,+) (-,+) (`footprint`). In the tangent frame at the looked-up
// direction d (t1 = normalize(y x d), t2 = d x t1) they are the ellipse's conjugate
// semi-diameters p, q; the projection's Jacobian J = d(u, v)/d(t1, t2) carries them to
// texels of level 0, and lod = log2 of the ellipse's major semi-axis there (0 below one
// texel), as OpenGL takes the longer derivative. The CPU takes J as the inverse of
// d(dir)/d(u, v) by differences of uv_to_dir; here J comes straight from envUv by central
// differences along t1 and t2 (one-sided where a step leaves the layer or wraps).
// CONE_CENTRE(uvl) is told the (u, v, layer) of each cone's centre (the simulator's record
// pass, sim-record.glsl, defines it).
#ifndef CONE_CENTRE
#define CONE_CENTRE(uvl)
#endif

uniform mat4 uView;
uniform vec3 uEye;
uniform bool uPersp;
uniform vec3 uForward;
uniform bool uAttachEye;
// The camera's rays: right and up scaled by the lens (tan(fov/2)·aspect, tan(fov/2), or the
// orthographic half extents): mirrorball-render's camera.rs `Rays`.
uniform vec3 uRayRight;
uniform vec3 uRayUp;

vec3 normalizeOrZero(vec3 v) {
    float l = length(v);
    return l > 0.0 ? v / l : vec3(0.0);
}

// World direction r to the environment's direction (`Prepared::attach32`).
vec3 attach(vec3 r) {
    return normalizeOrZero(uAttachEye ? mat3(uView) * r : r);
}

// The camera ray through window position `w` (pixels, y up): its origin and unit direction
// (camera.rs `Rays::ray`).
void cameraRay(vec2 w, out vec3 o, out vec3 d) {
    vec2 ndc = 2.0 * w / uViewportSize - 1.0;
    if (uPersp) {
        o = uEye;
        d = normalizeOrZero(uForward + uRayRight * ndc.x + uRayUp * ndc.y);
    } else {
        o = uEye + uRayRight * ndc.x + uRayUp * ndc.y;
        d = uForward;
    }
}

// The offsets of the pixel's corners, in the footprint's order.
const vec2 MB_CORNERS[4] = vec2[4](vec2(-0.5, -0.5), vec2(0.5, -0.5), vec2(0.5, 0.5), vec2(-0.5, 0.5));

// Barycentric coordinates of p in the plane of abc (render/cone.rs `barycentric`).
vec3 barycentric(vec3 a, vec3 b, vec3 c, vec3 p) {
    vec3 v0 = b - a;
    vec3 v1 = c - a;
    vec3 v2 = p - a;
    float d00 = dot(v0, v0);
    float d01 = dot(v0, v1);
    float d11 = dot(v1, v1);
    float d20 = dot(v2, v0);
    float d21 = dot(v2, v1);
    float den = d00 * d11 - d01 * d01;
    if (abs(den) < 1e-30) {
        return vec3(1.0, 0.0, 0.0);
    }
    float v = (d11 * d20 - d01 * d21) / den;
    float w = (d00 * d21 - d01 * d20) / den;
    return vec3(1.0 - v - w, v, w);
}

// The reflected ray at pixel corner k of the triangle (a, b, c) with normals (na, nb, nc);
// `n` is the normal at the pixel's centre, for a corner ray along the plane.
vec3 cornerReflection(int k, vec3 a, vec3 b, vec3 c, vec3 na, vec3 nb, vec3 nc, vec3 n) {
    vec3 o;
    vec3 d;
    cameraRay(gl_FragCoord.xy + MB_CORNERS[k], o, d);
    vec3 planeN = cross(b - a, c - a);
    float denom = dot(planeN, d);
    if (abs(denom) >= 1e-12) {
        vec3 p = o + d * (dot(planeN, a - o) / denom);
        vec3 w = barycentric(a, b, c, p);
        n = normalizeOrZero(na * w.x + nb * w.y + nc * w.z);
    }
    return d - 2.0 * dot(n, d) * n;
}

// d(u, v)/d(angle) at unit d along unit tangent t, by envUv; false where no step stays in the
// layer without wrapping.
const float MB_STEP = 1.0 / 512.0;
bool uvAlong(vec3 d, vec3 t, vec3 at, out vec2 j) {
    vec3 plus = envUv(normalize(d + MB_STEP * t));
    vec3 minus = envUv(normalize(d - MB_STEP * t));
    bool p = plus.z == at.z && all(lessThan(abs(plus.xy - at.xy), vec2(0.25)));
    bool m = minus.z == at.z && all(lessThan(abs(minus.xy - at.xy), vec2(0.25)));
    // normalize(d + h t) is atan(h) from d.
    float h = mbAtanPos(MB_STEP);
    if (p && m) {
        j = (plus.xy - minus.xy) / (2.0 * h);
    } else if (p) {
        j = (plus.xy - at.xy) / h;
    } else if (m) {
        j = (at.xy - minus.xy) / h;
    } else {
        return false;
    }
    return true;
}

// The footprint of a cone: the envUv of its centre direction d, the tangent frame (t1, t2)
// at d, and the ellipse's conjugate semi-diameters there (radians, p and q) and in level-0
// texels (a and b); `ok` is false for a point (a degenerate corner) or where the
// projection's Jacobian is not found.
struct Footprint {
    bool ok;
    vec3 at;
    vec3 t1;
    vec3 t2;
    vec2 p;
    vec2 q;
    vec2 a;
    vec2 b;
};

// The footprint of corner directions c (attached, unit) about unit d.
Footprint coneFootprint(vec3 d, vec3 c[4]) {
    Footprint f;
    f.ok = false;
    f.at = envUv(d);
    CONE_CENTRE(f.at);
    for (int k = 0; k < 4; k++) {
        if (!(dot(c[k], c[k]) >= 0.5) || any(isnan(c[k])) || any(isinf(c[k]))) {
            return f;
        }
    }
    vec3 dx = 0.5 * ((c[1] - c[0]) + (c[2] - c[3]));
    vec3 dy = 0.5 * ((c[3] - c[0]) + (c[2] - c[1]));
    f.t1 = vec3(d.z, 0.0, -d.x);
    f.t1 = dot(f.t1, f.t1) > 1e-20 ? normalize(f.t1) : vec3(1.0, 0.0, 0.0);
    f.t2 = cross(d, f.t1);
    f.p = vec2(dot(f.t1, dx), dot(f.t2, dx));
    f.q = vec2(dot(f.t1, dy), dot(f.t2, dy));
    vec2 j1;
    vec2 j2;
    if (f.at.z < 0.0 || !uvAlong(d, f.t1, f.at, j1) || !uvAlong(d, f.t2, f.at, j2)) {
        return f;
    }
    vec2 texels = vec2(uEnvSize);
    f.a = (j1 * f.p.x + j2 * f.p.y) * texels;
    f.b = (j1 * f.q.x + j2 * f.q.y) * texels;
    f.ok = true;
    return f;
}

// The semi-axes (major, minor) of the ellipse with conjugate semi-diameters a, b, and in
// `axis` the unit direction of the major one (sampler.rs `semi_axes`,
// `principal_directions`).
vec2 semiAxes(vec2 a, vec2 b, out vec2 axis) {
    float s00 = a.x * a.x + b.x * b.x;
    float s01 = a.x * a.y + b.x * b.y;
    float s11 = a.y * a.y + b.y * b.y;
    float disc = sqrt((s00 - s11) * (s00 - s11) + 4.0 * s01 * s01);
    float th = 0.5 * mbAtan2(2.0 * s01, s00 - s11);
    axis = vec2(cos(th), sin(th));
    return vec2(sqrt(max(0.5 * (s00 + s11 + disc), 0.0)), sqrt(max(0.5 * (s00 + s11 - disc), 0.0)));
}

// The environment filtered over the cone of corner directions c about d with the trilinear
// sampler (render/cone.rs `cone_read`, sampler.rs `Sampler::sample`): lod = log2 of the
// major semi-axis in level-0 texels, 0 below one texel or for a point.
vec3 coneRead(vec3 d, vec3 c[4]) {
    Footprint f = coneFootprint(d, c);
    float lod = 0.0;
    if (f.ok) {
        vec2 axis;
        float major = semiAxes(f.a, f.b, axis).x;
        lod = major > 1.0 ? log2(major) : 0.0;
    }
    return envTrilinear(f.at, lod);
}

// The most taps along the major axis, and the largest ratio of the axes before the minor one
// is widened (the CPU's `Sampler::max_anisotropy`).
#define MB_MAX_TAPS 32
const float MB_MAX_ANISOTROPY = 16.0;

// The environment filtered over the cone as anisotropic hardware filters a footprint, in the
// place of the CPU's EWA (sampler.rs `Sampler::ewa`: a Gaussian exp(-2r^2) - exp(-2) on the
// sphere, r = 1 on the ellipse): taps along the ellipse's major axis on the sphere (the
// directions normalize(d + tan(x R) e), R the major semi-axis in radians, e its tangent
// direction, x at the centres of n equal steps across (-1, 1)), weighted by the same
// Gaussian of x, each a trilinear read at lod = log2 of the minor semi-axis in level-0
// texels (the minor axis widened to 1/16 of the major as the CPU widens it), so that a tap
// blurs across the minor axis about as the Gaussian does there (a bilinear tent over box-
// filtered texels of size s has variance s^2/4, the Gaussian's is minor^2/4); n = 2
// major/minor taps (at most 32) keep them a texel of that level apart. Taps the projection
// does not cover are left out, as EWA leaves out texels of no solid angle. An approximation
// of EWA, not EWA: the taps lie on one line, and the level is one for the whole footprint.
vec3 coneReadAnisotropic(vec3 d, vec3 c[4]) {
    Footprint f = coneFootprint(d, c);
    if (!f.ok) {
        return envTrilinear(f.at, 0.0);
    }
    vec2 unused;
    vec2 texels = semiAxes(f.a, f.b, unused);
    float minor = max(texels.y, texels.x / MB_MAX_ANISOTROPY);
    float lod = minor > 1.0 ? log2(minor) : 0.0;
    int n = int(clamp(ceil(2.0 * texels.x / max(minor, 1.0)), 1.0, float(MB_MAX_TAPS)));
    if (n == 1) {
        return envTrilinear(f.at, lod);
    }
    vec2 e;
    float radius = min(semiAxes(f.p, f.q, e).x, 1.5);
    vec3 axis = f.t1 * e.x + f.t2 * e.y;
    vec3 sum = vec3(0.0);
    float wsum = 0.0;
    for (int i = 0; i < MB_MAX_TAPS; i++) {
        if (i >= n) {
            break;
        }
        float x = (2.0 * float(i) + 1.0) / float(n) - 1.0;
        vec3 uvl = envUv(normalize(d + axis * tan(radius * x)));
        if (uvl.z < 0.0) {
            continue;
        }
        float w = exp(-2.0 * x * x) - 0.1353352832366127;
        sum += w * envTrilinear(uvl, lod);
        wsum += w;
    }
    return wsum > 0.0 ? sum / wsum : vec3(0.0);
}
