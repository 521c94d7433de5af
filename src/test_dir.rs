//! Tests' own temporary directories: unit tests' in the system's temporary directory, the
//! integration tests' (tests/common includes this file) in Cargo's target/tmp.

use std::path::{Path, PathBuf};

/// A unit test's temporary directory, removed with everything in it when dropped (also when
/// the test fails).
pub struct TestDir(PathBuf);

impl TestDir {
    /// A new, empty directory named after this process and `name`, in the system's
    /// temporary directory.
    pub fn new(name: &str) -> Self {
        Self::new_in(&std::env::temp_dir(), name)
    }

    /// A new, empty directory named after this process and `name`, in `root`.
    pub fn new_in(root: &Path, name: &str) -> Self {
        let dir = root.join(format!("fovea-{}-{name}", std::process::id()));
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

impl AsRef<Path> for TestDir {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for TestDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
