// What every projection's envUv may use; comes first. The map's frame and parameters as the
// server describes them (crates/studio/src/state.rs `frame_of`, `params_of`), constants, and
// an accurate atan.
//
// atan: Cephes' single-precision atanf (S. L. Moshier, cephes/single/atanf.c; the f64 version
// is mirrorball-core's projection/fastmath.rs): |x| reduced to [0, tan(pi/8)] by
// atan x = pi/2 - atan(1/x) above tan(3pi/8) and pi/4 + atan((x - 1)/(x + 1)) above tan(pi/8),
// then its odd polynomial of degree 9 (relative error about 1e-7 on the reduced range). Used
// rather than the GPU's own atan, which is an approximation of unstated accuracy
// (SwiftShader's was off by up to 2e-4 in a disk map's radius).
// The frame as columns (right, up, axis): the disk maps' (radial.glsl) and the views'.
uniform mat3 uFrame;
// The projection's parameters, state.rs `params_of` says which.
uniform vec4 uParams;

const float MB_PI = 3.14159265358979;
const float MB_HALF_PI = 1.57079632679490;
// The envUv of a direction the map does not cover (layer -1).
const vec3 MB_NONE = vec3(0.0, 0.0, -1.0);

float mbAtanPos(float x) {
    float y0 = 0.0;
    if (x > 2.414213562373095) {
        y0 = MB_HALF_PI;
        x = -1.0 / x;
    } else if (x > 0.4142135623730950) {
        y0 = 0.25 * MB_PI;
        x = (x - 1.0) / (x + 1.0);
    }
    float z = x * x;
    return y0 + ((((8.05374449538e-2 * z - 1.38776856032e-1) * z + 1.99777106478e-1) * z
        - 3.33329491539e-1) * z * x + x);
}

// atan2(y, x) in [-pi, pi], atan2(0, 0) = 0: core fastmath.rs `atan2`.
float mbAtan2(float y, float x) {
    if (x == 0.0) {
        return y > 0.0 ? MB_HALF_PI : (y < 0.0 ? -MB_HALF_PI : 0.0);
    }
    float ay = abs(y);
    float ax = abs(x);
    float a = ay <= ax ? mbAtanPos(ay / ax) : MB_HALF_PI - mbAtanPos(ax / ay);
    a = x < 0.0 ? MB_PI - a : a;
    return y < 0.0 ? -a : a;
}

// 1 for x >= 0 (-0.0 included), else -1: the core's `sgn` (GLSL's sign(0) is 0).
float mbSign(float x) {
    return x >= 0.0 ? 1.0 : -1.0;
}

// The lat-long convention's longitude (ARCHITECTURE.md, core latlong.rs `u_of_dir`):
// atan2(x, -z), 0 along -Z, pi/2 along +X, +-pi along +Z. Cylinders, Mercator, Hammer and
// sinusoidal share it.
float mbLongitude(vec3 d) {
    return mbAtan2(d.x, -d.z);
}

// The latitude atan2(y, sqrt(x^2 + z^2)) (asin(y) without its loss of accuracy at the poles).
float mbLatitude(vec3 d) {
    return mbAtan2(d.y, sqrt(d.x * d.x + d.z * d.z));
}
