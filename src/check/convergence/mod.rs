//! Convergence of both integrators: root-mean-square error against a converged reference as
//! the sample count grows, for `pt` and `seed` on one scene.
//!
//! An unbiased Monte Carlo estimator's error falls as `spp^(-1/2)`, a line of slope −1/2 on a
//! log-log plot; a flatter line means bias (a floor), heavy tails (fireflies that few samples
//! miss) or correlated samples. The paths' numbers come from the independent sampler whatever
//! `--sampler` says: the −1/2 law is about independent samples. Between the integrators, `pt` should have the lower error both
//! at equal samples per pixel and at equal GPU time.
//!
//! Which reference for which number:
//! - **Slopes** are about each estimator's variance, so each integrator is measured against its
//!   *own* converged reference: a bias of `seed` (if any) would otherwise show as a floor that
//!   bends its line, and mix two questions into one number.
//! - **pt/seed ratios** are against the physically correct answer, `pt`'s reference, for both
//!   integrators: an error `seed` makes by converging to a different image is error.
//! - The difference between the two references is reported as `seed`'s **bias**
//!   ([`ReferenceBias`]), never hidden.
//!
//! References are the mean of several renders of [`REFERENCE_CHUNK_SPP`] samples with their own
//! seeds, like `bench::quality`'s. Their spread gives each pixel's variance of the reference
//! mean, and that variance is subtracted from every MSE: for a test image `x` independent of
//! the reference `r`, `E[(x − r)²] = E[(x − μ)²] + Var(r)`, so the corrected figure estimates
//! the error against the exact image and a finite reference does not flatten the slope at the
//! high-spp end. The uncorrected RMSE is kept beside it.

//!
//! One direction: `measure` renders and measures, its `chunks` accumulate the references, and
//! `fit` draws the lines; `options` (what to measure) and `results` (what was found, and its
//! report) are below them.

mod chunks;
pub mod fit;
pub mod measure;
pub mod options;
pub mod results;

pub use fit::LogLogFit;
pub use measure::measure;
pub use options::{ConvergenceOptions, REFERENCE_CHUNK_SPP};
pub use results::{Convergence, ConvergencePoint, IntegratorConvergence, ReferenceBias};
