//! Camera paths: what `fovea render --camera-path` renders, one frame per row. CSV with this
//! header:
//!
//! ```text
//! frame,dx,dy,dz,yaw_deg,pitch_deg,roll_deg
//! ```
//!
//! Each row is a pose relative to the scene's camera: `dx, dy, dz` move it along its own
//! right, up and forward axes (metres), then it turns by `yaw_deg` (positive: to the right),
//! `pitch_deg` (positive: up) and `roll_deg` (positive: clockwise as the viewer sees it), in
//! that order, about its own axes. Row k is frame k; the `frame` column documents the row
//! and must count up from 0.

use super::Camera;
use glam::Quat;
use std::path::{Path, PathBuf};

pub const HEADER: [&str; 7] = [
    "frame",
    "dx",
    "dy",
    "dz",
    "yaw_deg",
    "pitch_deg",
    "roll_deg",
];

/// One row: the camera's offset and turn from the scene camera.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CameraPose {
    pub offset: [f32; 3],
    /// Yaw, pitch and roll in degrees.
    pub turn_deg: [f32; 3],
}

impl CameraPose {
    /// The scene camera `camera` moved and turned by this pose (its field of view kept).
    pub fn apply(&self, camera: &Camera) -> Camera {
        let (r, u, f) = camera.basis();
        let [dx, dy, dz] = self.offset;
        let [yaw, pitch, roll] = self.turn_deg.map(f32::to_radians);
        // Intrinsic yaw → pitch → roll about the camera's axes is the product of the same
        // turns about the original axes in the opposite order. A right-handed turn about up
        // turns left, about right turns up, about forward turns the top to the right.
        let turn = Quat::from_axis_angle(u, -yaw)
            * Quat::from_axis_angle(r, pitch)
            * Quat::from_axis_angle(f, roll);
        Camera {
            position: camera.position + dx * r + dy * u + dz * f,
            forward: turn * f,
            up: turn * u,
            ..*camera
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum CameraPathError {
    #[error("cannot read the camera path '{path}': {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("the camera path '{path}' has no rows: write the header `{header}` and one row per frame", header = HEADER.join(","))]
    Empty { path: PathBuf },
    #[error("{path}, line {line}: {problem}")]
    Bad {
        path: PathBuf,
        line: usize,
        problem: String,
    },
}

/// A whole path, read and checked.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraPath {
    pub path: PathBuf,
    pub poses: Vec<CameraPose>,
}

impl CameraPath {
    pub fn read(path: &Path) -> Result<Self, CameraPathError> {
        let text = std::fs::read_to_string(path).map_err(|source| CameraPathError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        Self::parse(&text, path)
    }

    /// Parses a path's text; `path` is named in errors.
    pub fn parse(text: &str, path: &Path) -> Result<Self, CameraPathError> {
        let bad = |line: usize, problem: String| CameraPathError::Bad {
            path: path.to_path_buf(),
            line,
            problem,
        };
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, l.trim()))
            .filter(|(_, l)| !l.is_empty());
        let empty = || CameraPathError::Empty {
            path: path.to_path_buf(),
        };
        let (n, header) = lines.next().ok_or_else(empty)?;
        let names: Vec<&str> = header.split(',').map(str::trim).collect();
        if names != HEADER {
            return Err(bad(
                n,
                format!(
                    "the header must be `{}` (found `{header}`)",
                    HEADER.join(",")
                ),
            ));
        }
        let mut poses = Vec::new();
        for (n, line) in lines {
            let fields: Vec<&str> = line.split(',').map(str::trim).collect();
            if fields.len() != HEADER.len() {
                return Err(bad(
                    n,
                    format!(
                        "{} values where the header has {} columns",
                        fields.len(),
                        HEADER.len()
                    ),
                ));
            }
            if fields[0].parse::<usize>().ok() != Some(poses.len()) {
                return Err(bad(
                    n,
                    format!(
                        "frame '{}' where {} was expected: rows are frames 0, 1, 2, … in order",
                        fields[0],
                        poses.len()
                    ),
                ));
            }
            let mut values = [0f32; 6];
            for (c, v) in values.iter_mut().enumerate() {
                let text = fields[c + 1];
                *v = text
                    .parse::<f32>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| {
                        bad(
                            n,
                            format!("{} '{text}' is not a finite number", HEADER[c + 1]),
                        )
                    })?;
            }
            poses.push(CameraPose {
                offset: [values[0], values[1], values[2]],
                turn_deg: [values[3], values[4], values[5]],
            });
        }
        if poses.is_empty() {
            return Err(empty());
        }
        Ok(Self {
            path: path.to_path_buf(),
            poses,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn camera() -> Camera {
        Camera::look_at(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), Vec3::Y, 60.0, 1.0)
    }

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).length() < 1e-5
    }

    #[test]
    fn turns_and_moves_in_the_cameras_own_axes() {
        let c = camera();
        let pose = |offset, turn_deg| CameraPose { offset, turn_deg }.apply(&c);
        // Right is +x, up +y, forward -z for this camera.
        assert!(close(
            pose([1.0, 2.0, 3.0], [0.0; 3]).position,
            Vec3::new(1.0, 2.0, -3.0)
        ));
        assert!(close(pose([0.0; 3], [90.0, 0.0, 0.0]).forward, Vec3::X)); // yaw right
        assert!(close(pose([0.0; 3], [0.0, 90.0, 0.0]).forward, Vec3::Y)); // pitch up
        assert!(close(pose([0.0; 3], [0.0, 0.0, 90.0]).up, Vec3::X)); // roll clockwise
                                                                      // Yaw first, then pitch about the turned right axis: up and to the right.
        let both = pose([0.0; 3], [90.0, 45.0, 0.0]);
        assert!(close(both.forward, Vec3::new(1.0, 1.0, 0.0).normalize()));
    }

    #[test]
    fn rows_are_checked_with_their_line() {
        let p = Path::new("p.csv");
        let ok = CameraPath::parse(
            "frame,dx,dy,dz,yaw_deg,pitch_deg,roll_deg\n0,0,0,0,1,0,0\n1,0,0,0,2,0,0\n",
            p,
        )
        .unwrap();
        assert_eq!(ok.poses.len(), 2);
        assert_eq!(ok.poses[1].turn_deg, [2.0, 0.0, 0.0]);
        let err = |t: &str| CameraPath::parse(t, p).unwrap_err().to_string();
        assert!(err("frame,x\n").contains("the header must be"));
        assert!(err("frame,dx,dy,dz,yaw_deg,pitch_deg,roll_deg\n").contains("has no rows"));
        assert!(
            err("frame,dx,dy,dz,yaw_deg,pitch_deg,roll_deg\n1,0,0,0,0,0,0\n")
                .contains("line 2: frame '1' where 0")
        );
        assert!(
            err("frame,dx,dy,dz,yaw_deg,pitch_deg,roll_deg\n0,0,nan,0,0,0,0\n")
                .contains("dy 'nan' is not a finite number")
        );
        assert!(err("frame,dx,dy,dz,yaw_deg,pitch_deg,roll_deg\n0,0,0\n").contains("3 values"));
    }
}
