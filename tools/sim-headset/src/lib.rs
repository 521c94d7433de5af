//! The simulated headset (in progress).
