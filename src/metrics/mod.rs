//! Image error against a reference: MSE, relMSE, PSNR over the whole image and per
//! eccentricity band around the gaze, and FLIP.
