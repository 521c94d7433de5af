"""What an eccentricity-dependent blur would do to FovVideoVDP's score, on frames fovea already
rendered: a study of reconstruction, not part of the product.

Run a tune (or bench) with FOVEA_KEEP_JOD_INPUTS=DIR to keep every request it sends the metric,
then, with the FovVideoVDP venv's python (tools/setup-fvvdp.sh):

    .venv-fvvdp/bin/python tools/foveated-blur.py --mar 1,2 --guide reference DIR/PID-N.json ...

For each video request it prints the JOD as rendered and with every frame blurred: each pixel
by a Gaussian `MAR` minimum angles of resolution wide at its eccentricity from that frame's
fixation (Guenter et al. 2012: 0.022 deg per deg + 1/48 deg), in linear light. `--guide` says
where the blur stops: `none` (it crosses every edge), `reference` (the converged frame's
log2 luminance cut into half-stop bins; a pixel averages only its own bin's pixels: the best a
guide that knows every texture and shading edge could do) or `frame` (the same bins of the
noisy frame itself). Eccentricity uses the request's horizontal field of view over its width,
as FovVideoVDP's display geometry does.
"""
import argparse
import json

import numpy as np
import torch
import pyfvvdp
from pyfvvdp.fvvdp_display_model import fvvdp_display_geometry, fvvdp_display_photo_eotf
from scipy.ndimage import gaussian_filter

SIGMAS_PX = [0.0, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0]
BIN_STOPS = 0.5


def to_linear(x):
    return np.where(x <= 0.04045, x / 12.92, ((x + 0.055) / 1.055) ** 2.4)


def to_srgb(x):
    x = np.clip(x, 0.0, 1.0)
    return np.where(x <= 0.0031308, x * 12.92, 1.055 * x ** (1 / 2.4) - 0.055)


def blurred(frame, guide, sigma):
    """frame blurred by a Gaussian of sigma pixels, within the guide's luminance bins."""
    blur = lambda img: gaussian_filter(img, sigma)
    if guide is None:
        return np.stack([blur(frame[..., c]) for c in range(3)], -1)
    lum = np.log2(guide.mean(-1) + 1e-4)
    bins = np.floor((lum - lum.min()) / BIN_STOPS).astype(int)
    out = np.empty_like(frame)
    for b in np.unique(bins):
        inside = bins == b
        weight = blur(inside.astype(np.float32))
        for c in range(3):
            out[..., c][inside] = (blur(frame[..., c] * inside) / np.maximum(weight, 1e-6))[inside]
    return out


def foveated_blur(frame, guide, fixation, ppd, mar):
    h, w, _ = frame.shape
    yy, xx = np.mgrid[0:h, 0:w]
    ecc = np.hypot(xx + 0.5 - fixation[0], yy + 0.5 - fixation[1]) / ppd
    sigma = np.clip(mar * (0.022 * ecc + 1 / 48) * ppd, 0.0, SIGMAS_PX[-1])
    levels = np.stack([frame if s == 0 else blurred(frame, guide, s) for s in SIGMAS_PX])
    i = np.clip(np.searchsorted(SIGMAS_PX, sigma, side="right") - 1, 0, len(SIGMAS_PX) - 2)
    s0, s1 = np.array(SIGMAS_PX)[i], np.array(SIGMAS_PX)[i + 1]
    t = np.clip((sigma - s0) / (s1 - s0), 0.0, 1.0)[..., None]
    pick = lambda j: np.take_along_axis(levels, j[None, ..., None].repeat(3, -1), 0)[0]
    return pick(i) * (1 - t) + pick(i + 1) * t


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("requests", nargs="+", help="PID-N.json files kept by fovea")
    parser.add_argument("--mar", default="1,2", help="blur widths in minimum angles of resolution")
    parser.add_argument("--guide", choices=["none", "reference", "frame"], default="reference")
    args = parser.parse_args()
    widths = [float(m) for m in args.mar.split(",")]
    metrics = {}
    for path in args.requests:
        r = json.load(open(path))
        f, h, w = r["frames"], r["height"], r["width"]
        if f < 2:
            continue  # a first frame: the study is of videos
        test = np.fromfile(r["test"], "<f4").reshape(f, h, w, 3)
        ref = np.fromfile(r["reference"], "<f4").reshape(f, h, w, 3)
        key = (w, h, r["fov_horizontal_deg"], r["peak_cd_m2"], r["black_cd_m2"])
        if key not in metrics:
            geometry = fvvdp_display_geometry((w, h), distance_m=3.0, fov_horizontal=key[2])
            photometry = fvvdp_display_photo_eotf(key[3], contrast=key[3] / key[4], EOTF="sRGB")
            metrics[key] = pyfvvdp.fvvdp(display_photometry=photometry, display_geometry=geometry,
                                         foveated=True, quiet=True, heatmap=None,
                                         device=torch.device("cpu"))
        fixation = torch.tensor(r["fixation"], dtype=torch.float32)

        def score(frames):
            with torch.no_grad():
                q, _ = metrics[key].predict(torch.from_numpy(frames), torch.from_numpy(ref),
                                            dim_order="FHWC", frames_per_second=r["fps"],
                                            fixation_point=fixation)
            return float(q)

        line = [f"{path}: as rendered {score(test):.3f}"]
        ppd = w / r["fov_horizontal_deg"]
        guides = {"none": None, "reference": ref, "frame": test}[args.guide]
        for mar in widths:
            frames = [to_srgb(foveated_blur(to_linear(test[k]),
                                            None if guides is None else to_linear(guides[k]),
                                            r["fixation"][k], ppd, mar)) for k in range(f)]
            line.append(f"{mar} MAR ({args.guide}) {score(np.stack(frames).astype(np.float32)):.3f}")
        print(", ".join(line), flush=True)


if __name__ == "__main__":
    main()
