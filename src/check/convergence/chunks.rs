//! A reference as the mean of equal-spp chunks, and the chunks' spread as the noise of that
//! mean (see the module docs of `convergence`).

/// Running per-float sums of equal-spp chunk images: their mean and the variance of that mean.
pub(super) struct Accumulator {
    sum: Vec<f64>,
    sum_sq: Vec<f64>,
    chunk_means: Vec<[f64; 3]>,
}

impl Accumulator {
    pub(super) fn new(len: usize) -> Self {
        Self {
            sum: vec![0.0; len],
            sum_sq: vec![0.0; len],
            chunk_means: Vec::new(),
        }
    }
    pub(super) fn add(&mut self, rgb: &[f32]) {
        for ((s, q), &v) in self.sum.iter_mut().zip(&mut self.sum_sq).zip(rgb) {
            *s += v as f64;
            *q += v as f64 * v as f64;
        }
        self.chunk_means.push(channel_means(rgb));
    }
    fn k(&self) -> f64 {
        self.chunk_means.len() as f64
    }
    pub(super) fn mean(&self) -> Vec<f32> {
        self.sum.iter().map(|s| (s / self.k()) as f32).collect()
    }
    /// Mean over floats of the estimated variance of the per-float mean.
    pub(super) fn noise_mse(&self) -> f64 {
        let k = self.k();
        let total: f64 = self
            .sum
            .iter()
            .zip(&self.sum_sq)
            .map(|(s, q)| ((q - s * s / k) / (k - 1.0)).max(0.0) / k)
            .sum();
        total / self.sum.len() as f64
    }
    /// Per channel: the image mean and the variance of that mean, from the chunks' means.
    pub(super) fn image_mean(&self) -> [(f64, f64); 3] {
        let k = self.k();
        std::array::from_fn(|c| {
            let m = self.chunk_means.iter().map(|v| v[c]).sum::<f64>() / k;
            let var = self
                .chunk_means
                .iter()
                .map(|v| (v[c] - m).powi(2))
                .sum::<f64>()
                / (k - 1.0);
            (m, var / k)
        })
    }
}

fn channel_means(rgb: &[f32]) -> [f64; 3] {
    let mut sum = [0.0f64; 3];
    for p in rgb.chunks_exact(3) {
        for c in 0..3 {
            sum[c] += p[c] as f64;
        }
    }
    let n = (rgb.len() / 3).max(1) as f64;
    sum.map(|s| s / n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reference_noise_is_the_variance_of_the_mean() {
        // Two chunks per float: 1 and 3 → variance 2, variance of the mean 1.
        let mut acc = Accumulator::new(3);
        acc.add(&[1.0, 1.0, 1.0]);
        acc.add(&[3.0, 3.0, 3.0]);
        assert_eq!(acc.mean(), vec![2.0; 3]);
        assert!((acc.noise_mse() - 1.0).abs() < 1e-12);
        let [(m, v), _, _] = acc.image_mean();
        assert_eq!((m, v), (2.0, 1.0));
    }
}
