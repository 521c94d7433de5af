//! How many trace threads each layer's lattice points get (GpuLayer::lanes). One thread per
//! point traces the point's samples one after another, starting the next as soon as one
//! ends; a GPU then sees too few threads for a sparse layer of many samples (a fovea): on an
//! H100 the thesis' layers traced 3–4× fewer samples per second than regular 1 spp
//! (reports/gpu-h100-1440x1600). Lanes spread a point's samples over threads; each lane
//! should keep several, or it idles while its workgroup's longest path runs, and a layer of
//! 1 spp gets nothing from them (reports/gpu-h100-split-1440x1600). And a GPU wants enough
//! threads in flight: on an H200 a layer of 144 000 points of 4 samples (one thread each)
//! traced at half the rate per ray of 576 000 points of 1 (reports/gpu-h200-candidates-720x800),
//! so a frame of few points gets more lanes until each eye's trace fills the GPU.

use crate::shader_layout::MAX_TRACE_LANES;

/// The rule: layer lanes = the largest power of two ≤ spp / `samples_per_lane`, at least 1,
/// at most `max_lanes`; then, while an eye's trace has fewer than `fill_threads` threads,
/// the layer whose threads keep the most samples gets twice its lanes (at most its spp and
/// `max_lanes`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TraceLanes {
    pub max_lanes: u32,
    pub samples_per_lane: u32,
    /// Threads per eye the trace should have at least (0: no filling).
    pub fill_threads: u64,
}

impl TraceLanes {
    /// One thread per point: what a CPU driver runs best, where threads add work, not
    /// parallelism.
    pub const ONE: Self = Self {
        max_lanes: 1,
        samples_per_lane: 1,
        fill_threads: 0,
    };

    /// Checked: `max_lanes` a power of two up to MAX_TRACE_LANES, `samples_per_lane` ≥ 1; no
    /// filling (`with_fill_threads`).
    pub fn new(max_lanes: u32, samples_per_lane: u32) -> Result<Self, String> {
        if !max_lanes.is_power_of_two() || max_lanes > MAX_TRACE_LANES {
            return Err(format!(
                "trace split {max_lanes}: give a power of two from 1 to {MAX_TRACE_LANES} \
                 (the most threads per lattice point)"
            ));
        }
        if samples_per_lane == 0 {
            return Err("samples per lane 0: give at least 1".into());
        }
        Ok(Self {
            max_lanes,
            samples_per_lane,
            fill_threads: 0,
        })
    }

    /// The same rule, filling each eye's trace up to `threads` threads.
    pub fn with_fill_threads(self, threads: u64) -> Self {
        Self {
            fill_threads: threads,
            ..self
        }
    }

    /// Threads for each point of a layer of `spp` samples.
    pub fn of_layer(&self, spp: u32) -> u32 {
        let wanted = (spp / self.samples_per_lane).max(1);
        (1u32 << wanted.ilog2()).min(self.max_lanes)
    }

    /// Threads for each point of each layer, given the layers' spp and how many points each
    /// traces per eye (`points`: with the gaze ahead; the filling needs only its size).
    pub fn of_layers(&self, spp: &[u32], points: &[u64]) -> Vec<u32> {
        let mut lanes: Vec<u32> = spp.iter().map(|&s| self.of_layer(s)).collect();
        let threads =
            |lanes: &[u32]| -> u64 { lanes.iter().zip(points).map(|(&l, &p)| l as u64 * p).sum() };
        while threads(&lanes) < self.fill_threads {
            // The layer whose threads keep the most samples, among those that can split again
            // (the first of equals: the innermost).
            let splittable = (0..lanes.len())
                .filter(|&k| points[k] > 0 && 2 * lanes[k] <= spp[k].min(self.max_lanes));
            let Some(k) = splittable.max_by_key(|&k| (spp[k] / lanes[k], std::cmp::Reverse(k)))
            else {
                break;
            };
            lanes[k] *= 2;
        }
        lanes
    }
}

/// The most lanes of the layers: the plan pads each run's work-list slots to a multiple of
/// it (GpuLayer::lane_unit), and the work lists are sized for that padding.
pub fn lane_unit(layer_lanes: &[u32]) -> u32 {
    layer_lanes.iter().copied().max().unwrap_or(1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_are_powers_of_two_within_the_cap_and_the_samples() {
        let lanes = TraceLanes::new(8, 2).unwrap();
        let got: Vec<u32> = [1, 2, 3, 4, 7, 8, 16, 17, 64, 1000]
            .iter()
            .map(|&spp| lanes.of_layer(spp))
            .collect();
        assert_eq!(got, [1, 1, 1, 2, 2, 4, 8, 8, 8, 8]);
        assert_eq!(TraceLanes::ONE.of_layer(1000), 1);
        assert!(TraceLanes::new(3, 1).is_err());
        assert!(TraceLanes::new(128, 1).is_err());
        assert!(TraceLanes::new(4, 0).is_err());
    }

    #[test]
    fn filling_splits_the_layers_of_most_samples_per_thread_until_the_eye_has_enough_threads() {
        let rule = TraceLanes::new(16, 4).unwrap();
        let (spp, points) = ([4, 2, 1], [100_000, 50_000, 200_000]);
        assert_eq!(
            rule.of_layers(&spp, &points),
            [1, 1, 1],
            "no filling asked for"
        );
        // 350 000 threads; the fovea (4 samples a thread) splits first, then the fovea and the
        // 2-spp layer hold 2 a thread each: the innermost goes first.
        let fill = |t| rule.with_fill_threads(t).of_layers(&spp, &points);
        assert_eq!(fill(350_000), [1, 1, 1]);
        assert_eq!(fill(400_000), [2, 1, 1]);
        assert_eq!(fill(500_000), [4, 1, 1]);
        assert_eq!(fill(650_000), [4, 1, 1]);
        assert_eq!(fill(650_001), [4, 2, 1]);
        // Every layer down to one sample a thread: nothing more to split.
        assert_eq!(fill(10_000_000), [4, 2, 1]);
        // A layer with no points never takes lanes; the cap holds.
        let capped = TraceLanes::new(2, 1).unwrap().with_fill_threads(1 << 30);
        assert_eq!(capped.of_layers(&[64, 64], &[0, 10]), [2, 2]);
        assert_eq!(
            TraceLanes::new(16, 4)
                .unwrap()
                .with_fill_threads(1 << 30)
                .of_layers(&[64, 8], &[0, 10]),
            [16, 8]
        );
    }
}
