// The simulator's record pass (sim.js): put between interpolate.glsl and cone.glsl, it
// makes the viewport's own fragment stage write, instead of a colour, the (u, v, layer) its
// one environment read took: every read goes through envRead (bilinear.glsl; mode 4's cone
// names its centre through CONE_CENTRE, cone.glsl), and the colour through display
// (display.glsl), so those names are routed here. Drawn into an
// RGBA32F target; the clear colour (0, 0, -2, 0) marks pixels no object covers.
vec3 simRead = vec3(0.0, 0.0, -1.0);

vec3 simRecord(vec3 uvl) {
    simRead = uvl;
    return envRead(uvl);
}

vec3 simShow(vec3 c) {
    return simRead;
}

#define envRead simRecord
// Mode 4 (cone.glsl): the cone's centre.
#define CONE_CENTRE(uvl) simRead = (uvl)
#define display simShow
