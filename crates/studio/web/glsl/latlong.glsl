// Lat-long: direction -> (u, v, layer), as mirrorball-core's projection/latlong.rs
// (`LatLong::dir_to_uv`): u = atan2(x, -z)/2pi + 1/2 (u = 1/2 looks along -Z, 3/4 along +X,
// 0 and 1 along +Z), v = 1/2 - atan2(y, sqrt(x^2 + z^2))/pi (row 0 is +Y). Scale-invariant.
const float MB_PI = 3.14159265358979;

vec3 envUv(vec3 d) {
    float u = atan(d.x, -d.z) * (0.5 / MB_PI) + 0.5;
    float v = 0.5 - atan(d.y, sqrt(d.x * d.x + d.z * d.z)) * (1.0 / MB_PI);
    return vec3(u, v, 0.0);
}
