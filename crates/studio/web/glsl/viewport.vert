// The viewport's vertex stage. Prepended by gl.js: the version, MODE (1 texgen, 2 per-vertex
// reflection, 3 per pixel), TEXGEN (mode 1: 0 GL_SPHERE_MAP, 1 GL_REFLECTION_MAP, 2 a
// single-layer map's own (u, v)), BACKGROUND, the projection's envUv and texgen.glsl.
// Vertices come in world space (the server flattens the objects as the CPU renderer does).
// The per-vertex formulas are mirrorball-render's render/vertex.rs (mode 2) and
// render/texgen.rs (mode 1, `per_vertex`).
in vec3 aPos;
in vec3 aNrm;

uniform mat4 uView;
uniform mat4 uProj;
uniform vec3 uEye;
uniform bool uPersp;
// The camera's forward (view) direction, world space.
uniform vec3 uForward;
uniform bool uAttachEye;

out vec3 vPos;
out vec3 vNrm;
// Mode 2: the reflected vector; mode 1: the texgen output ((u, v) in .xy, or a direction).
out vec3 vR;

vec3 normalizeOrZero(vec3 v) {
    float l = length(v);
    return l > 0.0 ? v / l : vec3(0.0);
}

void main() {
#if BACKGROUND
    // One triangle over the whole viewport.
    vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2)) * 2.0 - 1.0;
    gl_Position = vec4(p, 1.0, 1.0);
    vPos = vec3(0.0);
    vNrm = vec3(0.0);
    vR = vec3(0.0);
#else
    vec4 pe = uView * vec4(aPos, 1.0);
    gl_Position = uProj * pe;
    vPos = aPos;
    vNrm = aNrm;
    vR = vec3(0.0);
#if MODE == 2
    vec3 v = uPersp ? normalizeOrZero(aPos - uEye) : uForward;
    vR = v - 2.0 * dot(aNrm, v) * aNrm;
#elif MODE == 1
    // Eye space, as the fixed-function pipeline: u = normalize(P_eye).
    mat3 rot = mat3(uView);
    vec3 u = normalizeOrZero(pe.xyz);
    vec3 ne = normalizeOrZero(rot * aNrm);
    vec3 rEye = u - 2.0 * dot(ne, u) * ne;
    vec3 d = uAttachEye ? rEye : transpose(rot) * rEye;
#if TEXGEN == 0
    // The sphere map's camera frame: (right.d, up.d, -forward.d) = transpose(uFrame) d.
    vec2 st = glSphereSt(transpose(uFrame) * d);
    vR = vec3(st.x, 1.0 - st.y, 0.0);
#elif TEXGEN == 2
    vec3 uvl = envUv(normalizeOrZero(d));
    vR = uvl.z < 0.0 ? vec3(uintBitsToFloat(0x7fc00000u)) : vec3(uvl.xy, 0.0);
#else
    vR = d;
#endif
#endif
#endif
}
