//! Convergence of the integrators: RMSE against a converged reference as spp grows.
