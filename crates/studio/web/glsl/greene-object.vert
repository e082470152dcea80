// Greene live's meshes (greene.js): a moving object, or the mirror sphere's bounding box,
// in world space by uModel, seen by uViewProj (a face of the capture, or the panel's camera).
layout(location = 0) in vec3 aPos;
layout(location = 1) in vec3 aNormal;

uniform mat4 uModel;
uniform mat4 uViewProj;

out vec3 vWorld;
out vec3 vNormal;

void main() {
    vec4 w = uModel * vec4(aPos, 1.0);
    vWorld = w.xyz;
    // uModel is a rotation times a uniform scale: its 3x3 part carries normals.
    vNormal = mat3(uModel) * aNormal;
    gl_Position = uViewProj * w;
}
