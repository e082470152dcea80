// Mercator: direction -> (u, v, layer), as mirrorball-core's projection/latlong.rs
// (`Mercator::dir_to_uv`): the lat-long's u; ordinate y = atanh(sin(latitude)),
// atanh s = log((1 + s)/(1 - s))/2, v = (1 - y/Y_max)/2. Not covered beyond the latitude
// limit: |sin(latitude)| > tanh Y_max, with a margin of 1e-6 for the f32 direction, clamped.
// uParams = (Y_max, tanh Y_max). Comes after math.glsl.
vec3 envUv(vec3 d) {
    float len = length(d);
    if (!(len > 0.0)) {
        return MB_NONE;
    }
    float s = d.y / len;
    if (abs(s) > uParams.y * (1.0 + 1e-6)) {
        return MB_NONE;
    }
    s = clamp(s, -uParams.y, uParams.y);
    float y = 0.5 * log((1.0 + s) / (1.0 - s));
    return vec3(mbLongitude(d) * (0.5 / MB_PI) + 0.5, 0.5 * (1.0 - y / uParams.x), 0.0);
}
