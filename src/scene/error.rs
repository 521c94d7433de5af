use std::path::PathBuf;

/// Why a scene could not be built or loaded. Every message says what was wrong and what to do.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error("unknown scene '{name}': use one of {known} (see `fovea scenes`), or give the path of a .gltf/.glb file")]
    UnknownScene { name: String, known: String },
    #[error("cannot load '{}': {problem}", path.display())]
    Load { path: PathBuf, problem: String },
    #[error("invalid scene '{scene}': {problem}")]
    Invalid { scene: String, problem: String },
}
