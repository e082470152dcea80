// The simulator's surface pass (sim.js), after viewport.vert's outputs and interpolate.glsl:
// each covered pixel's world position and unit normal, interpolated as viewport.frag
// interpolates them, into two RGBA32F targets (alpha 1 where covered).
flat in vec4 vClip0;
flat in vec4 vClip1;
flat in vec4 vClip2;
flat in vec3 vP0;
flat in vec3 vP1;
flat in vec3 vP2;
flat in vec3 vN0;
flat in vec3 vN1;
flat in vec3 vN2;

layout(location = 0) out vec4 outPosition;
layout(location = 1) out vec4 outNormal;

void main() {
    vec3 b = cornerWeights(vClip0, vClip1, vClip2);
    outPosition = vec4(b.x * vP0 + b.y * vP1 + b.z * vP2, 1.0);
    vec3 n = b.x * vN0 + b.y * vN1 + b.z * vN2;
    float l = length(n);
    outNormal = vec4(l > 0.0 ? n / l : vec3(0.0), 1.0);
}
