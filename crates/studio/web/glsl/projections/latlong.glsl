// Lat-long: direction -> (u, v, layer), as mirrorball-core's projection/latlong.rs
// (`LatLong::dir_to_uv`): u = longitude/2pi + 1/2 (u = 1/2 looks along -Z, 3/4 along +X,
// 0 and 1 along +Z), v = 1/2 - latitude/pi (row 0 is +Y). Scale-invariant. Comes after
// math.glsl.
vec3 envUv(vec3 d) {
    return vec3(mbLongitude(d) * (0.5 / MB_PI) + 0.5, 0.5 - mbLatitude(d) * (1.0 / MB_PI), 0.0);
}
