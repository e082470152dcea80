// The viewport's vertex stage. Prepended by gl.js: the version, MODE (1 texgen, 2 per-vertex
// reflection, 3 per pixel), TEXGEN (mode 1: 0 GL_SPHERE_MAP, 1 GL_REFLECTION_MAP, 2 a
// single-layer map's own (u, v)), BACKGROUND, the projection's envUv and texgen.glsl.
// Vertices come in world space (the server flattens the objects as the CPU renderer does),
// each with its triangle's three corners (aP*, aN*): the stage computes the per-vertex
// values of all three corners (`perVertex`: mirrorball-render's render/vertex.rs for mode 2,
// render/texgen.rs `per_vertex` for mode 1) and hands them, with the corners' clip
// coordinates, to the fragment stage, which interpolates them perspective-correctly
// (interpolate.glsl).
in vec3 aPos;
in vec3 aP0;
in vec3 aP1;
in vec3 aP2;
in vec3 aN0;
in vec3 aN1;
in vec3 aN2;

uniform mat4 uView;
uniform mat4 uProj;
uniform vec3 uEye;
uniform bool uPersp;
// The camera's forward (view) direction, world space.
uniform vec3 uForward;
uniform bool uAttachEye;

flat out vec4 vClip0;
flat out vec4 vClip1;
flat out vec4 vClip2;
flat out vec3 vP0;
flat out vec3 vP1;
flat out vec3 vP2;
flat out vec3 vN0;
flat out vec3 vN1;
flat out vec3 vN2;
// The corners' per-vertex values: mode 2 the reflected vector; mode 1 the texgen output
// ((u, v) in .xy, or a direction).
flat out vec3 vC0;
flat out vec3 vC1;
flat out vec3 vC2;

vec3 normalizeOrZero(vec3 v) {
    float l = length(v);
    return l > 0.0 ? v / l : vec3(0.0);
}

vec3 perVertex(vec3 p, vec3 n) {
#if MODE == 2
    vec3 v = uPersp ? normalizeOrZero(p - uEye) : uForward;
    return v - 2.0 * dot(n, v) * n;
#elif MODE == 1
    // Eye space, as the fixed-function pipeline: u = normalize(P_eye).
    mat3 rot = mat3(uView);
    vec3 u = normalizeOrZero((uView * vec4(p, 1.0)).xyz);
    vec3 ne = normalizeOrZero(rot * n);
    vec3 rEye = u - 2.0 * dot(ne, u) * ne;
    vec3 d = uAttachEye ? rEye : transpose(rot) * rEye;
#if TEXGEN == 0
    // The sphere map's camera frame: (right.d, up.d, -forward.d) = transpose(uFrame) d.
    vec2 st = glSphereSt(transpose(uFrame) * d);
    return vec3(st.x, 1.0 - st.y, 0.0);
#elif TEXGEN == 2
    vec3 uvl = envUv(normalizeOrZero(d));
    return uvl.z < 0.0 ? vec3(uintBitsToFloat(0x7fc00000u)) : vec3(uvl.xy, 0.0);
#else
    return d;
#endif
#else
    return vec3(0.0);
#endif
}

vec4 clip(vec3 p) {
    return uProj * (uView * vec4(p, 1.0));
}

void main() {
#if BACKGROUND
    // One triangle over the whole viewport.
    vec2 q = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2)) * 2.0 - 1.0;
    gl_Position = vec4(q, 1.0, 1.0);
#else
    gl_Position = clip(aPos);
#endif
    vClip0 = clip(aP0);
    vClip1 = clip(aP1);
    vClip2 = clip(aP2);
    vP0 = aP0;
    vP1 = aP1;
    vP2 = aP2;
    vN0 = aN0;
    vN1 = aN1;
    vN2 = aN2;
    vC0 = perVertex(aP0, aN0);
    vC1 = perVertex(aP1, aN1);
    vC2 = perVertex(aP2, aN2);
}
