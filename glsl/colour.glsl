// Colour helpers shared by the passes that weigh or show pixels.
#ifndef FOVEA_COLOUR_GLSL
#define FOVEA_COLOUR_GLSL

// Relative luminance of linear Rec. 709 RGB.
float luminance(vec3 c) {
    return dot(c, vec3(0.2126, 0.7152, 0.0722));
}

// Interpolating high-dynamic-range values between sparse samples: a lamp next to a dim
// ceiling makes a linear cubic bleed the lamp's radiance several pixels out (the lamp looks
// bigger) and ring beyond it. Each sample is weighed by 1 / (1 + luminance) instead: the
// interpolation runs on (x w, w) and the value is their ratio, so an edge between any two
// radiances is blended about as the display blends it (Karis' weighting, "High-quality
// temporal supersampling", 2014), while dim, smooth signals are nearly untouched.
vec4 hdr_weighted(vec3 x) {
    return vec4(x, 1.0) / (1.0 + max(luminance(x), 0.0));
}

// The radiance of an interpolated hdr_weighted value (whose weight the caller kept within
// its samples' range, so above 0).
vec3 hdr_unweighted(vec4 y) {
    return max(y.rgb, vec3(0.0)) / max(y.a, 1e-6);
}

#endif
