//! Gaze trace files: what `--record-gaze` writes and `--gaze-trace` replays. CSV, one row per
//! frame, with this header:
//!
//! ```text
//! frame,time_s,left_tan_x,left_tan_y,right_tan_x,right_tan_y,status
//! ```
//!
//! Gaze is stored per eye in the eye's tangent space (x right, y up, as `view` has it), not in
//! pixels, so one trace replays at any resolution and field of view. `status` is `tracked`,
//! `held` (the filter's last good gaze), `centre` (the view axis; its tangents may be NaN)
//! or `fixed` (a gaze given on the command line). Replay takes row k for frame k: the `frame`
//! and `time_s` columns document the recording and are not used to pick rows.
//!
//! The writer flushes every line, so an interrupted session keeps everything it recorded.

use super::gaze::Gaze;
use super::gaze_filter::GazeStatus;
use super::view::ImageGeometry;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The header line, column by column.
pub const HEADER: [&str; 7] = [
    "frame",
    "time_s",
    "left_tan_x",
    "left_tan_y",
    "right_tan_x",
    "right_tan_y",
    "status",
];

/// Where a row's gaze came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TraceStatus {
    Tracked,
    Held,
    Centre,
    Fixed,
}

impl TraceStatus {
    pub const ALL: [TraceStatus; 4] = [
        TraceStatus::Tracked,
        TraceStatus::Held,
        TraceStatus::Centre,
        TraceStatus::Fixed,
    ];

    pub fn name(self) -> &'static str {
        match self {
            TraceStatus::Tracked => "tracked",
            TraceStatus::Held => "held",
            TraceStatus::Centre => "centre",
            TraceStatus::Fixed => "fixed",
        }
    }

    pub fn parse(text: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.name() == text)
    }
}

impl From<GazeStatus> for TraceStatus {
    fn from(s: GazeStatus) -> Self {
        match s {
            GazeStatus::Tracked => TraceStatus::Tracked,
            GazeStatus::Held { .. } => TraceStatus::Held,
            GazeStatus::Centre => TraceStatus::Centre,
        }
    }
}

/// One frame's gaze.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TraceRow {
    pub frame: u64,
    pub time_s: f64,
    /// Tangent-space gaze of each eye.
    pub left: [f64; 2],
    pub right: [f64; 2],
    pub status: TraceStatus,
}

impl TraceRow {
    /// Each eye's gaze (eye 0 the left, eye 1 the right; a single eye uses the left columns)
    /// as a pixel of its image; a centre row is the view axis.
    pub fn gazes(&self, images: &[ImageGeometry]) -> Vec<Gaze> {
        images
            .iter()
            .enumerate()
            .map(|(e, image)| {
                if self.status == TraceStatus::Centre {
                    return Gaze::Forward;
                }
                let p = image.pixel_of(if e == 1 { self.right } else { self.left });
                Gaze::Pixel(p[0], p[1])
            })
            .collect()
    }

    fn line(&self) -> String {
        format!(
            "{},{:?},{:?},{:?},{:?},{:?},{}\n",
            self.frame,
            self.time_s,
            self.left[0],
            self.left[1],
            self.right[0],
            self.right[1],
            self.status.name()
        )
    }
}

/// Why a trace could not be read or written. Messages name the file, and for bad content
/// the line and column, and say what the file should hold.
#[derive(Debug, thiserror::Error)]
pub enum GazeTraceError {
    #[error("cannot read gaze trace {}: {source}", path.display())]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("cannot write gaze trace {}: {source}", path.display())]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error(
        "gaze trace {} is empty: it needs the header `{}` and at least one row",
        path.display(),
        HEADER.join(",")
    )]
    Empty { path: PathBuf },
    #[error("gaze trace {}, line {line}, column {column} ({name}): {problem}", path.display())]
    Bad {
        path: PathBuf,
        /// 1-based.
        line: usize,
        /// 1-based.
        column: usize,
        /// The column's header name.
        name: &'static str,
        problem: String,
    },
}

/// A whole trace, read and checked.
#[derive(Clone, Debug, PartialEq)]
pub struct GazeTrace {
    pub path: PathBuf,
    pub rows: Vec<TraceRow>,
}

impl GazeTrace {
    pub fn read(path: &Path) -> Result<Self, GazeTraceError> {
        let text = std::fs::read_to_string(path).map_err(|source| GazeTraceError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        Self::parse(&text, path)
    }

    /// Parses the text of a trace; `path` is named in errors.
    pub fn parse(text: &str, path: &Path) -> Result<Self, GazeTraceError> {
        let bad = |line: usize, column: usize, problem: String| GazeTraceError::Bad {
            path: path.to_path_buf(),
            line,
            column: column + 1,
            name: HEADER[column.min(HEADER.len() - 1)],
            problem,
        };
        // Blank lines (a trailing newline, an editor's extra one) carry nothing.
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, l.trim()))
            .filter(|(_, l)| !l.is_empty());
        let Some((n, header)) = lines.next() else {
            return Err(GazeTraceError::Empty {
                path: path.to_path_buf(),
            });
        };
        let names: Vec<&str> = header.split(',').map(str::trim).collect();
        if let Some(c) = (0..HEADER.len().max(names.len()))
            .find(|&c| names.get(c).copied() != HEADER.get(c).copied())
        {
            return Err(bad(
                n,
                c,
                format!(
                    "the header must be `{}` (found `{header}`)",
                    HEADER.join(",")
                ),
            ));
        }
        let mut rows = Vec::new();
        for (n, line) in lines {
            let fields: Vec<&str> = line.split(',').map(str::trim).collect();
            if fields.len() != HEADER.len() {
                return Err(bad(
                    n,
                    fields.len().min(HEADER.len() - 1),
                    format!(
                        "{} values where the header has {} columns",
                        fields.len(),
                        HEADER.len()
                    ),
                ));
            }
            let status = TraceStatus::parse(fields[6]).ok_or_else(|| {
                bad(
                    n,
                    6,
                    format!(
                        "'{}' is not a status: use tracked, held, centre or fixed",
                        fields[6]
                    ),
                )
            })?;
            let frame = fields[0]
                .parse::<u64>()
                .map_err(|_| bad(n, 0, format!("'{}' is not a whole frame number", fields[0])))?;
            let number = |c: usize| {
                fields[c]
                    .parse::<f64>()
                    .map_err(|_| bad(n, c, format!("'{}' is not a number", fields[c])))
            };
            let time_s = number(1)?;
            if !time_s.is_finite() {
                return Err(bad(
                    n,
                    1,
                    "the time must be a finite number of seconds".into(),
                ));
            }
            let mut tan = [0.0; 4];
            for (k, v) in tan.iter_mut().enumerate() {
                *v = number(2 + k)?;
                // NaN says "no gaze", which only a centre row may say; ∞ is never a gaze.
                let allowed = v.is_finite() || (v.is_nan() && status == TraceStatus::Centre);
                if !allowed {
                    return Err(bad(
                        n,
                        2 + k,
                        format!(
                            "{v} is not a usable tangent; only a row with status centre may \
                             leave its gaze as NaN"
                        ),
                    ));
                }
            }
            rows.push(TraceRow {
                frame,
                time_s,
                left: [tan[0], tan[1]],
                right: [tan[2], tan[3]],
                status,
            });
        }
        if rows.is_empty() {
            return Err(GazeTraceError::Empty {
                path: path.to_path_buf(),
            });
        }
        Ok(Self {
            path: path.to_path_buf(),
            rows,
        })
    }

    /// The row of frame `frame` (the frame-th row), and whether the trace had ended and its
    /// last row stands in.
    pub fn row(&self, frame: u64) -> (&TraceRow, bool) {
        match self.rows.get(frame as usize) {
            Some(row) => (row, false),
            None => (self.rows.last().expect("a trace has rows"), true),
        }
    }
}

/// Writes a trace line by line.
pub struct TraceWriter {
    path: PathBuf,
    file: std::fs::File,
}

impl TraceWriter {
    /// Creates (or truncates) `path` and writes the header.
    pub fn create(path: &Path) -> Result<Self, GazeTraceError> {
        let err = |source| GazeTraceError::Write {
            path: path.to_path_buf(),
            source,
        };
        let mut file = std::fs::File::create(path).map_err(err)?;
        file.write_all(format!("{}\n", HEADER.join(",")).as_bytes())
            .map_err(err)?;
        Ok(Self {
            path: path.to_path_buf(),
            file,
        })
    }

    /// Appends one row, written through to the file at once (unbuffered). A row the reader
    /// would reject (non-finite tangents outside a centre row, a non-finite time) is an error.
    pub fn write(&mut self, row: &TraceRow) -> Result<(), GazeTraceError> {
        let line = row.line();
        // The reader is the one definition of a valid row.
        GazeTrace::parse(&format!("{}\n{line}", HEADER.join(",")), &self.path).map_err(
            |e| match e {
                GazeTraceError::Bad {
                    column,
                    name,
                    problem,
                    ..
                } => GazeTraceError::Write {
                    path: self.path.clone(),
                    source: std::io::Error::new(
                        std::io::ErrorKind::InvalidInput,
                        format!(
                            "row of frame {} column {column} ({name}): {problem}",
                            row.frame
                        ),
                    ),
                },
                other => other,
            },
        )?;
        self.file
            .write_all(line.as_bytes())
            .map_err(|source| GazeTraceError::Write {
                path: self.path.clone(),
                source,
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::foveation::EyeFov;

    fn parse(text: &str) -> Result<GazeTrace, GazeTraceError> {
        GazeTrace::parse(text, Path::new("t.csv"))
    }

    const HEAD: &str = "frame,time_s,left_tan_x,left_tan_y,right_tan_x,right_tan_y,status\n";

    #[test]
    fn rows_parse_and_replay_into_each_eyes_pixels() {
        let text = format!(
            "{HEAD}0,0,0.5,-0.25,0.4,-0.25,tracked\n1, 0.011 ,-0.1,0.2,-0.2,0.2,held\n\n\
             2,0.022,NaN,NaN,NaN,NaN,centre\n"
        );
        let trace = parse(&text).unwrap();
        assert_eq!(trace.rows.len(), 3);
        assert_eq!(trace.rows[1].time_s, 0.011);
        assert_eq!(trace.rows[1].status, TraceStatus::Held);
        let images = [
            ImageGeometry::new(64, 48, EyeFov::VIVE_PRO_EYE_LEFT),
            ImageGeometry::new(64, 48, EyeFov::VIVE_PRO_EYE_RIGHT),
        ];
        let g = trace.rows[0].gazes(&images);
        let (l, r) = (
            images[0].pixel_of([0.5, -0.25]),
            images[1].pixel_of([0.4, -0.25]),
        );
        assert_eq!(g, vec![Gaze::Pixel(l[0], l[1]), Gaze::Pixel(r[0], r[1])]);
        // Mono uses the left columns; centre is the view axis whatever the values.
        assert_eq!(trace.rows[0].gazes(&images[1..]).len(), 1);
        let p = images[1].pixel_of([0.5, -0.25]);
        assert_eq!(
            trace.rows[0].gazes(&images[1..])[0],
            Gaze::Pixel(p[0], p[1])
        );
        assert_eq!(trace.rows[2].gazes(&images), vec![Gaze::Forward; 2]);
        // Past the end the last row stands in, and says so.
        assert_eq!(trace.row(1), (&trace.rows[1], false));
        let (last, past_end) = trace.row(99);
        assert!(std::ptr::eq(last, &trace.rows[2]) && past_end);
    }

    /// The error's line, column and message.
    fn error(text: &str) -> (usize, usize, String) {
        match parse(text).unwrap_err() {
            GazeTraceError::Bad {
                line,
                column,
                problem,
                ..
            } => (line, column, problem),
            other => panic!("{other}"),
        }
    }

    #[test]
    fn bad_input_names_line_and_column() {
        let (l, c, p) = error("frame,time,left_tan_x\n");
        assert_eq!((l, c), (1, 2), "{p}");
        assert!(p.contains("header must be"), "{p}");
        let (l, c, p) = error(&format!(
            "{HEAD}0,0,0,0,0,0,tracked\n1,0.1,0.2,abc,0,0,tracked\n"
        ));
        assert_eq!((l, c), (3, 4));
        assert!(p.contains("'abc' is not a number"), "{p}");
        let (l, c, p) = error(&format!("{HEAD}0,0,NaN,0,0,0,tracked\n"));
        assert_eq!((l, c), (2, 3));
        assert!(p.contains("only a row with status centre"), "{p}");
        let (_, c, _) = error(&format!("{HEAD}0,0,0,0,inf,0,centre\n"));
        assert_eq!(c, 5);
        let (_, c, p) = error(&format!("{HEAD}0,0,0,0,0,0,blinking\n"));
        assert_eq!(c, 7);
        assert!(p.contains("tracked, held, centre or fixed"), "{p}");
        let (_, c, p) = error(&format!("{HEAD}0,0,0,0\n"));
        assert_eq!(c, 5, "the first missing column");
        assert!(p.contains("4 values"), "{p}");
        let (_, c, _) = error(&format!("{HEAD}-1,0,0,0,0,0,fixed\n"));
        assert_eq!(c, 1);
        let (_, c, _) = error(&format!("{HEAD}0,NaN,0,0,0,0,fixed\n"));
        assert_eq!(c, 2);
        for empty in ["", "\n\n", HEAD] {
            let e = parse(empty).unwrap_err();
            assert!(matches!(e, GazeTraceError::Empty { .. }), "{e}");
            assert!(e.to_string().contains("t.csv"), "{e}");
        }
        let e = parse(&format!("{HEAD}0,0,x,0,0,0,fixed\n"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("t.csv, line 2, column 3 (left_tan_x)"), "{e}");
    }

    #[test]
    fn written_rows_read_back_bit_for_bit_and_survive_an_interruption() {
        let dir = crate::test_dir::TestDir::new("gaze-trace");
        let path = dir.join("gaze.csv");
        let rows = [
            TraceRow {
                frame: 0,
                time_s: 0.0,
                left: [0.1 + 0.2, -1.0 / 3.0],
                right: [1e-300, -0.0],
                status: TraceStatus::Tracked,
            },
            TraceRow {
                frame: 1,
                time_s: 0.0111,
                left: [f64::NAN; 2],
                right: [f64::NAN; 2],
                status: TraceStatus::Centre,
            },
        ];
        let mut w = TraceWriter::create(&path).unwrap();
        w.write(&rows[0]).unwrap();
        // Read while the writer is still open: the row is already in the file.
        assert_eq!(GazeTrace::read(&path).unwrap().rows, vec![rows[0]]);
        w.write(&rows[1]).unwrap();
        let bad = TraceRow {
            left: [f64::NAN, 0.0],
            status: TraceStatus::Held,
            ..rows[0]
        };
        let e = w.write(&bad).unwrap_err().to_string();
        assert!(e.contains("only a row with status centre"), "{e}");
        drop(w);
        let back = GazeTrace::read(&path).unwrap().rows;
        assert_eq!(back[0], rows[0]);
        assert!(back[1].left[0].is_nan() && back[1].status == TraceStatus::Centre);
        assert_eq!(back.len(), 2);
        std::fs::remove_file(&path).unwrap();
        let e = GazeTrace::read(&path).unwrap_err().to_string();
        assert!(
            e.contains("cannot read gaze trace") && e.contains("gaze.csv"),
            "{e}"
        );
    }
}
