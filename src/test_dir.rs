//! Unit tests' own temporary directories (the integration tests have tests/common's).

use std::path::{Path, PathBuf};

/// A unit test's temporary directory, removed with everything in it when dropped (also when
/// the test fails).
pub struct TestDir(PathBuf);

impl TestDir {
    /// A new, empty directory named after this process and `name`.
    pub fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("fovea-unit-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("create the test's temporary directory");
        Self(dir)
    }
}

impl std::ops::Deref for TestDir {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl Drop for TestDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
