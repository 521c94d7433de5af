"""FovVideoVDP (pyfvvdp) for fovea: one JSON request per line on stdin, one JSON answer per line
on stdout. fovea starts this with the venv's python (see tools/setup-fvvdp.sh) and keeps it for
a whole run, so torch is imported once.

Request: {"width", "height", "frames", "fps" (0 for an image), "test", "reference" (paths of
raw little-endian float32 files, frames x height x width x RGB, display-encoded sRGB in 0..1),
"fixation" ([[x, y]] per frame, pixels from the top-left), "peak_cd_m2" and "black_cd_m2" (the
display's luminance at 1 and 0: its photometry, an sRGB display as pyfvvdp models one from its
display_models.json entries), "fov_horizontal_deg" (the image's horizontal field of view, for its
geometry)}. Answer: {"jod": float} or {"error": "what went wrong"}.
"""
import json
import sys


def main():
    try:
        import numpy as np
        import torch
        import pyfvvdp
        from pyfvvdp.fvvdp_display_model import fvvdp_display_geometry, fvvdp_display_photo_eotf
    except Exception as e:  # a broken venv: say so on the protocol, then stop
        print(json.dumps({"error": f"cannot import pyfvvdp: {e}"}), flush=True)
        return 1
    # One thread per core is torch's default; fovea runs the GPU driver beside it.
    print(json.dumps({"ready": True, "torch": torch.__version__, "numpy": np.__version__}), flush=True)
    metrics = {}

    def metric(peak, black, width, height, fov):
        key = (peak, black, width, height, round(fov, 6))
        if key not in metrics:
            geometry = fvvdp_display_geometry((width, height), distance_m=3.0, fov_horizontal=fov)
            # What fvvdp_display_photometry.load builds from a display_models.json entry with
            # max_luminance and min_luminance (sRGB EOTF, gamma 2.2, no ambient light).
            photometry = fvvdp_display_photo_eotf(peak, contrast=peak / black, EOTF="sRGB")
            metrics[key] = pyfvvdp.fvvdp(
                display_photometry=photometry,
                display_geometry=geometry,
                foveated=True,
                quiet=True,
                heatmap=None,
                device=torch.device("cpu"),
            )
        return metrics[key]

    for line in sys.stdin:
        if not line.strip():
            continue
        try:
            r = json.loads(line)
            w, h, f = int(r["width"]), int(r["height"]), int(r["frames"])
            shape = (f, h, w, 3)
            test = np.fromfile(r["test"], dtype="<f4").reshape(shape)
            ref = np.fromfile(r["reference"], dtype="<f4").reshape(shape)
            fixation = torch.tensor(r["fixation"], dtype=torch.float32)
            if fixation.shape != (f, 2):
                raise ValueError(f"fixation has shape {tuple(fixation.shape)}, needs ({f}, 2)")
            peak, black = float(r["peak_cd_m2"]), float(r["black_cd_m2"])
            if not (peak > black > 0):
                raise ValueError(f"display luminance {black}..{peak} cd/m^2: needs peak > black > 0")
            m = metric(peak, black, w, h, float(r["fov_horizontal_deg"]))
            fps = float(r["fps"])
            with torch.no_grad():
                if f == 1:
                    q, _ = m.predict(torch.from_numpy(test[0]), torch.from_numpy(ref[0]),
                                     dim_order="HWC", fixation_point=fixation[0])
                else:
                    q, _ = m.predict(torch.from_numpy(test), torch.from_numpy(ref),
                                     dim_order="FHWC", frames_per_second=fps,
                                     fixation_point=fixation)
            answer = {"jod": float(q)}
        except Exception as e:
            answer = {"error": f"{type(e).__name__}: {e}"}
        print(json.dumps(answer), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
