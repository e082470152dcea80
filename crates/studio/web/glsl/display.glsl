// Linear radiance to the displayed colour, as `mirrorball render` writes a PNG:
// mirrorball-render's tone.rs (`to_display`: times 2^exposure, then `Tone::apply`: non-finite
// and negative values to 0, then clamp, Reinhard x/(1 + x) or Narkowicz's ACES fit
// x(2.51x + 0.03)/(x(2.43x + 0.59) + 0.14) clipped to [0, 1]; core color.rs) and the sRGB
// encoding (core color.rs, IEC 61966-2-1: 12.92 l below 0.0031308, else
// 1.055 l^(1/2.4) - 0.055). The framebuffer rounds to 8 bits as `srgb8_f32` does.
uniform float uExposureScale;
// 0: clamp, 1: Reinhard, 2: ACES.
uniform int uTone;

float toneCurve(float x) {
    x = (isnan(x) || isinf(x)) ? 0.0 : max(x, 0.0);
    if (uTone == 0) {
        return min(x, 1.0);
    } else if (uTone == 1) {
        return x / (1.0 + x);
    }
    return clamp(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

float srgbEncode(float l) {
    l = clamp(l, 0.0, 1.0);
    return l <= 0.0031308 ? 12.92 * l : 1.055 * pow(l, 1.0 / 2.4) - 0.055;
}

vec3 display(vec3 c) {
    return vec3(
        srgbEncode(toneCurve(c.r * uExposureScale)),
        srgbEncode(toneCurve(c.g * uExposureScale)),
        srgbEncode(toneCurve(c.b * uExposureScale)));
}
