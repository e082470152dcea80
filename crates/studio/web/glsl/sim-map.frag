// The simulator's map picture (sim.js): the environment in its layout, one picture pixel a
// texel, read at texel centres through envRead (bilinear.glsl, so exactly the stored texel)
// and shown as display.glsl shows the viewport. Layer k's cell is uCells[k] of a grid of
// uGrid cells, each uEnvSize texels; pixels in no cell are transparent.
uniform ivec2 uGrid;
uniform ivec2 uCells[6];
uniform int uLayers;

out vec4 outColor;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    // Target row y (read back first for y = 0) is the picture's row y, top first.
    ivec2 cell = p / uEnvSize;
    for (int k = 0; k < 6; k++) {
        if (k < uLayers && uCells[k] == cell) {
            vec2 uv = (vec2(p - cell * uEnvSize) + 0.5) / vec2(uEnvSize);
            outColor = vec4(display(envRead(vec3(uv, float(k)))), 1.0);
            return;
        }
    }
    outColor = vec4(0.0);
}
