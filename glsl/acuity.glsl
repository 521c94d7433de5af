// The minimum angle of resolution against eccentricity (radians against radians): Guenter et
// al. 2012's fit, 0.022 deg per deg of eccentricity plus 1/48 deg at the centre (the host's
// copy, with tests: src/foveation/acuity.rs). lattice_filter.comp and denoise.comp size their
// blur by it.
#ifndef FOVEA_ACUITY_GLSL
#define FOVEA_ACUITY_GLSL
#include "view.glsl"

const float MAR_SLOPE = 0.022;
const float MAR_CENTRE = (1.0 / 48.0) * 3.14159265 / 180.0;

float minimum_angle_of_resolution(float eccentricity) {
    return MAR_SLOPE * eccentricity + MAR_CENTRE;
}

// The minimum angle of resolution in direction u (unit) for an eye looking along `gaze`, in
// steps of the image there: `next` is the direction one step (a pixel, a lattice step) to
// the right, and the image's steps are square.
float acuity_in_steps(vec3 u, vec3 next, vec3 gaze) {
    float step_angle = max(length(next - u), 1e-9);
    return minimum_angle_of_resolution(angle_of(u, gaze)) / step_angle;
}

#endif
