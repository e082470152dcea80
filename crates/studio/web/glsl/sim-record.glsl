// The simulator's record pass (sim.js): put between interpolate.glsl and cone.glsl, it
// makes the viewport's own fragment stage write, instead of a colour, the (u, v, layer) its
// one environment read took: every read goes through envRead or (mode 4) envTrilinear
// (bilinear.glsl), and the colour through display (display.glsl), so those names are routed
// here. Drawn into an
// RGBA32F target; the clear colour (0, 0, -2, 0) marks pixels no object covers.
vec3 simRead = vec3(0.0, 0.0, -1.0);

vec3 simRecord(vec3 uvl) {
    simRead = uvl;
    return envRead(uvl);
}

vec3 simShow(vec3 c) {
    return simRead;
}

// Mode 4's read: the cone's centre, filtered as the viewport filters it.
vec3 simRecordCone(vec3 uvl, float lod) {
    simRead = uvl;
    return envTrilinear(uvl, lod);
}

#define envRead simRecord
#define envTrilinear simRecordCone
#define display simShow
