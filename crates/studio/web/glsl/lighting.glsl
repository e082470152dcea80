// The prefiltered materials (MATERIAL 1: GGX, 2: Lambert), after bilinear.glsl: the
// server's chain (crates/studio/src/lighting.rs, made as `mirrorball prefilter --lobe ggx`
// makes it) and the SH9 of E/π (the filter crate's sh.rs). The chain is a cube with its mip
// levels, read by the GPU's trilinear filter at the level the server gave for the slider's
// roughness (`levelOf`: the filter crate's `RoughnessMapping::level`); WebGL2 filters cubes
// seamlessly across faces. The SH is Σ cᵢ Kᵢ mᵢ(n): the page uploads cᵢ Kᵢ (the
// coefficients times sh.rs `CONSTANTS`), the monomials mᵢ are sh.rs `basis`'s, in its order.
precision highp samplerCube;

uniform samplerCube uChain;
// The chain's level for the slider's roughness (fractional: trilinear).
uniform float uLevel;
// cᵢ Kᵢ, i = 0 … 8.
uniform vec3 uSh[9];

// The chain in direction d, times the environment's intensity.
vec3 chainRead(vec3 d) {
    return textureLod(uChain, d, uLevel).rgb * uIntensity;
}

// E/π at unit normal n, times the environment's intensity.
vec3 irradiance(vec3 n) {
    float x = n.x;
    float y = n.y;
    float z = n.z;
    vec3 e = uSh[0]
        + uSh[1] * y + uSh[2] * z + uSh[3] * x
        + uSh[4] * (x * y) + uSh[5] * (y * z) + uSh[6] * (3.0 * z * z - 1.0)
        + uSh[7] * (x * z) + uSh[8] * (x * x - y * y);
    return e * uIntensity;
}
