//! Where the data came from (errors name it) and the kinds of ignored content (reported once).

use std::collections::BTreeSet;
use std::path::Path;

use crate::scene::SceneError;

/// Where the data came from; turns problems into errors that name it.
pub(super) struct Origin<'a> {
    pub(super) path: &'a Path,
}

impl Origin<'_> {
    /// A problem with the file itself (missing, unreadable, not glTF, truncated, missing buffers).
    pub(super) fn load(&self, problem: String) -> SceneError {
        SceneError::Load {
            path: self.path.to_path_buf(),
            problem,
        }
    }
    /// A problem with the content (bad indices, NaN vertices, nothing to render).
    pub(super) fn invalid(&self, problem: String) -> SceneError {
        SceneError::Invalid {
            scene: self.path.display().to_string(),
            problem,
        }
    }
}

/// Kinds of ignored features, reported once each at the end of a load.
#[derive(Default)]
pub(super) struct Warnings(BTreeSet<String>);

impl Warnings {
    pub(super) fn add(&mut self, kind: impl Into<String>) {
        self.0.insert(kind.into());
    }
    pub(super) fn emit(&self, origin: &Origin) {
        for kind in &self.0 {
            tracing::warn!("{}: ignoring {kind}", origin.path.display());
        }
    }
}
