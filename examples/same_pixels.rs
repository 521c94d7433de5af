//! Do two directories hold the same images, pixel for pixel? Every `.exr` under OLD (at any
//! depth) is read beside the file of the same name under NEW and their RGBA f32 values
//! compared bit for bit. The files' bytes may differ where their pixels do not (older fovea
//! binaries wrote EXR chunks in whatever order the compressing threads finished).
//!
//!   cargo run --release --example same_pixels -- OLD_DIR NEW_DIR
//!
//! Prints each differing or missing file; exit status 1 if any, 0 if all are identical.

use std::path::{Path, PathBuf};

fn exr_files(dir: &Path, found: &mut Vec<PathBuf>) -> std::io::Result<()> {
    for entry in std::fs::read_dir(dir)? {
        let path = entry?.path();
        if path.is_dir() {
            exr_files(&path, found)?;
        } else if path.extension().is_some_and(|e| e == "exr") {
            found.push(path);
        }
    }
    Ok(())
}

/// The image's size and its pixels' RGBA bits, row-major.
fn pixels(path: &Path) -> Result<(usize, usize, Vec<u32>), String> {
    let image = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |size, _| (size.width(), vec![0u32; size.width() * size.height() * 4]),
        |(w, bits), pos, (r, g, b, a): (f32, f32, f32, f32)| {
            let i = 4 * (pos.y() * *w + pos.x());
            bits[i..i + 4].copy_from_slice(&[r.to_bits(), g.to_bits(), b.to_bits(), a.to_bits()]);
        },
    )
    .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let size = image.layer_data.size;
    Ok((
        size.width(),
        size.height(),
        image.layer_data.channel_data.pixels.1,
    ))
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [old, new] = args.as_slice() else {
        eprintln!("usage: same_pixels OLD_DIR NEW_DIR");
        std::process::exit(2);
    };
    let mut files = Vec::new();
    if let Err(e) = exr_files(Path::new(old), &mut files) {
        eprintln!("cannot list {old}: {e}");
        std::process::exit(2);
    }
    files.sort();
    let mut differ = 0;
    for file in &files {
        let name = file.strip_prefix(old).expect("found under OLD");
        let verdict = match (pixels(file), pixels(&Path::new(new).join(name))) {
            (Ok(a), Ok(b)) if a == b => None,
            (Ok(a), Ok(b)) if (a.0, a.1) != (b.0, b.1) => {
                Some(format!("size {}x{} against {}x{}", a.0, a.1, b.0, b.1))
            }
            (Ok(a), Ok(b)) => {
                let px =
                    a.2.chunks(4)
                        .zip(b.2.chunks(4))
                        .filter(|(p, q)| p != q)
                        .count();
                Some(format!("{px} of {} pixels differ", a.0 * a.1))
            }
            (Err(e), _) | (_, Err(e)) => Some(e),
        };
        if let Some(why) = verdict {
            println!("DIFFERS: {} ({why})", name.display());
            differ += 1;
        }
    }
    println!("{} images compared, {differ} differ", files.len());
    std::process::exit(if differ > 0 || files.is_empty() { 1 } else { 0 });
}
