//! How many frames may be in flight: the frame slots that per-frame host data (layers, plan
//! dispatch, timestamps, counter read-backs, history views, descriptor sets) is kept in.

/// Frame slots: the most frames a renderer keeps in flight. Two let the CPU's and the GPU's
/// work overlap; a third absorbs a frame whose CPU side runs long (a slow xrWaitFrame).
pub const MAX_FRAMES_IN_FLIGHT: usize = 3;
