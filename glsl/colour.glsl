// Colour helpers shared by the passes that weigh or show pixels.
#ifndef FOVEA_COLOUR_GLSL
#define FOVEA_COLOUR_GLSL

// Relative luminance of linear Rec. 709 RGB.
float luminance(vec3 c) {
    return dot(c, vec3(0.2126, 0.7152, 0.0722));
}

#endif
