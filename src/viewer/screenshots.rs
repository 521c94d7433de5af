//! Saving screenshots: the frame shown written through the session, and free file names for
//! the screenshot key.

use super::app::App;
use super::error::ViewError;
use std::path::{Path, PathBuf};

impl App {
    pub(super) fn save_screenshot(&mut self, path: &Path) -> Result<(), ViewError> {
        for written in self.session.screenshot(path)? {
            println!("wrote {}", written.display());
            self.summary.screenshots.push(written);
        }
        Ok(())
    }
}

/// `path` with `-1`, `-2`, … before its extension: the first that does not exist.
pub(super) fn next_free_name(path: &Path) -> PathBuf {
    let stem = path.file_stem().unwrap_or_default().to_string_lossy();
    let ext = path
        .extension()
        .map_or("png".into(), |e| e.to_string_lossy());
    (1..)
        .map(|i| path.with_file_name(format!("{stem}-{i}.{ext}")))
        .find(|p| !p.exists())
        .expect("some name is free")
}
