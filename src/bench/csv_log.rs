//! A CSV file that rows are appended to as they are measured, flushed after every row, so an
//! interrupted run keeps everything it finished. Reopening it returns the rows already there
//! and drops a last line cut off mid-write (the only damage a kill can do to an append).

use serde::{de::DeserializeOwned, Serialize};
use std::fs::{File, OpenOptions};
use std::io::BufWriter;
use std::marker::PhantomData;
use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum CsvLogError {
    #[error("{path}: {problem}")]
    Io { path: String, problem: String },
    #[error(
        "{path}, line {line}: {problem}. The file is not a fovea bench log of this version; \
         start a new run instead of resuming this one"
    )]
    Corrupt {
        path: String,
        line: u64,
        problem: String,
    },
}

pub struct CsvLog<T> {
    path: PathBuf,
    writer: csv::Writer<BufWriter<File>>,
    _rows: PhantomData<T>,
}

fn io_error(path: &Path, e: impl std::fmt::Display) -> CsvLogError {
    CsvLogError::Io {
        path: path.display().to_string(),
        problem: e.to_string(),
    }
}

impl<T: Serialize + DeserializeOwned> CsvLog<T> {
    /// Opens `path` for appending, creating it (with a header) if missing. Returns the log and
    /// the complete rows it already holds.
    pub fn open(path: &Path) -> Result<(Self, Vec<T>), CsvLogError> {
        Self::open_keeping(path, |rows| rows)
    }

    /// Like [`Self::open`], keeping only the rows `keep` returns (e.g. dropping the first
    /// eye of a frame whose second eye was never written); the file is rewritten without
    /// the others.
    pub fn open_keeping(
        path: &Path,
        keep: impl FnOnce(Vec<T>) -> Vec<T>,
    ) -> Result<(Self, Vec<T>), CsvLogError> {
        let (rows, torn) = if path.exists() {
            read_complete_rows(path)?
        } else {
            (Vec::new(), true)
        };
        let read = rows.len();
        let rows = keep(rows);
        if torn || rows.len() != read {
            // Write header and good rows to a new file and move it over the old one: a torn
            // line must not stay in front of the rows appended after it, and a kill during
            // the rewrite leaves the old file whole.
            let temp = path.with_extension("csv.partial");
            let file = File::create(&temp).map_err(|e| io_error(&temp, e))?;
            let mut writer = csv::WriterBuilder::new()
                .has_headers(false)
                .from_writer(BufWriter::new(file));
            writer
                .write_record(header_of::<T>())
                .map_err(|e| io_error(&temp, e))?;
            for row in &rows {
                writer.serialize(row).map_err(|e| io_error(&temp, e))?;
            }
            writer.flush().map_err(|e| io_error(&temp, e))?;
            drop(writer);
            std::fs::rename(&temp, path).map_err(|e| io_error(path, e))?;
        }
        let file = OpenOptions::new()
            .append(true)
            .open(path)
            .map_err(|e| io_error(path, e))?;
        let log = Self {
            path: path.to_path_buf(),
            writer: csv::WriterBuilder::new()
                .has_headers(false)
                .from_writer(BufWriter::new(file)),
            _rows: PhantomData,
        };
        Ok((log, rows))
    }

    /// Appends one row and flushes it to the file.
    pub fn append(&mut self, row: &T) -> Result<(), CsvLogError> {
        self.writer
            .serialize(row)
            .map_err(|e| io_error(&self.path, e))?;
        self.writer.flush().map_err(|e| io_error(&self.path, e))
    }
}

/// The header row `csv` would write for `T`: its field names, found by serializing nothing
/// but the names (serde's struct serialization reports them in order).
fn header_of<T: DeserializeOwned>() -> Vec<&'static str> {
    struct Names(Vec<&'static str>);
    impl<'de> serde::Deserializer<'de> for &mut Names {
        type Error = serde::de::value::Error;
        fn deserialize_any<V: serde::de::Visitor<'de>>(
            self,
            _: V,
        ) -> Result<V::Value, Self::Error> {
            Err(serde::de::Error::custom("field names only"))
        }
        fn deserialize_struct<V: serde::de::Visitor<'de>>(
            self,
            _name: &'static str,
            fields: &'static [&'static str],
            _visitor: V,
        ) -> Result<V::Value, Self::Error> {
            self.0.extend_from_slice(fields);
            Err(serde::de::Error::custom("field names only"))
        }
        serde::forward_to_deserialize_any! {
            bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string
            bytes byte_buf option unit unit_struct newtype_struct seq tuple
            tuple_struct map enum identifier ignored_any
        }
    }
    let mut names = Names(Vec::new());
    let _ = T::deserialize(&mut names);
    names.0
}

/// Every row of `path` up to the first one that does not parse, which must be the last line
/// (a write cut off by a kill); a bad row followed by good ones means the file is not ours.
/// Also says whether such a cut-off line was found.
fn read_complete_rows<T: DeserializeOwned>(path: &Path) -> Result<(Vec<T>, bool), CsvLogError> {
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .flexible(true)
        .from_path(path)
        .map_err(|e| io_error(path, e))?;
    let header = reader.headers().map_err(|e| io_error(path, e))?.clone();
    let expected = header_of::<T>();
    if header.is_empty() {
        // Killed before the header reached the disk: an empty log.
        return Ok((Vec::new(), true));
    }
    if header.iter().collect::<Vec<_>>() != expected {
        return Err(CsvLogError::Corrupt {
            path: path.display().to_string(),
            line: 1,
            problem: format!("its columns are not {}", expected.join(",")),
        });
    }
    let mut rows = Vec::new();
    let mut bad: Option<(u64, String)> = None;
    for record in reader.deserialize::<T>() {
        match (record, &bad) {
            (Ok(row), None) => rows.push(row),
            (Err(e), None) => {
                let line = e.position().map(|p| p.line()).unwrap_or(0);
                bad = Some((line, e.to_string()));
            }
            (_, Some((line, problem))) => {
                return Err(CsvLogError::Corrupt {
                    path: path.display().to_string(),
                    line: *line,
                    problem: problem.clone(),
                })
            }
        }
    }
    if let Some((line, problem)) = &bad {
        tracing::warn!(
            "{}: dropped a cut-off last line ({line}: {problem}); it is measured again",
            path.display()
        );
    }
    Ok((rows, bad.is_some()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_dir::TestDir;
    use serde::Deserialize;

    #[derive(Debug, PartialEq, Serialize, Deserialize)]
    struct Row {
        name: String,
        n: u32,
        ms: f64,
    }

    /// A test directory (removed when dropped) and the log's path in it.
    fn temp(name: &str) -> (TestDir, PathBuf) {
        let dir = TestDir::new(&format!("csv-log-{name}"));
        let path = dir.join("rows.csv");
        (dir, path)
    }

    fn row(n: u32) -> Row {
        Row {
            name: format!("r{n}"),
            n,
            ms: n as f64 * 1.5,
        }
    }

    #[test]
    fn rows_survive_reopening_and_the_header_is_written_once() {
        let (_dir, path) = temp("reopen");
        let _ = std::fs::remove_file(&path);
        {
            let (log, rows) = CsvLog::<Row>::open(&path).unwrap();
            assert!(rows.is_empty());
            drop(log);
            assert_eq!(std::fs::read_to_string(&path).unwrap(), "name,n,ms\n");
        }
        {
            let (mut log, _) = CsvLog::<Row>::open(&path).unwrap();
            log.append(&row(1)).unwrap();
            log.append(&row(2)).unwrap();
            // Flushed per row: readable while the log is still open.
            let text = std::fs::read_to_string(&path).unwrap();
            assert_eq!(text.lines().count(), 3, "{text}");
        }
        let (mut log, rows) = CsvLog::<Row>::open(&path).unwrap();
        assert_eq!(rows, vec![row(1), row(2)]);
        log.append(&row(3)).unwrap();
        drop(log);
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(text.matches("name,n,ms").count(), 1, "{text}");
        assert_eq!(text.lines().count(), 4);
    }

    #[test]
    fn a_line_cut_off_by_a_kill_is_dropped() {
        let (_dir, path) = temp("torn");
        std::fs::write(&path, "name,n,ms\nr1,1,1.5\nr2,2,3.0\nr3,3").unwrap();
        let (mut log, rows) = CsvLog::<Row>::open(&path).unwrap();
        assert_eq!(rows, vec![row(1), row(2)]);
        log.append(&row(3)).unwrap();
        drop(log);
        let (_, rows) = CsvLog::<Row>::open(&path).unwrap();
        assert_eq!(rows, vec![row(1), row(2), row(3)]);
    }

    #[test]
    fn rows_not_kept_leave_the_file() {
        let (_dir, path) = temp("keep");
        std::fs::write(&path, "name,n,ms\nr1,1,1.5\nr2,2,3.0\n").unwrap();
        let (_, rows) = CsvLog::<Row>::open_keeping(&path, |rows| {
            rows.into_iter().filter(|r| r.n != 2).collect()
        })
        .unwrap();
        assert_eq!(rows, vec![row(1)]);
        assert_eq!(
            std::fs::read_to_string(&path).unwrap(),
            "name,n,ms\nr1,1,1.5\n"
        );
    }

    #[test]
    fn an_empty_file_gets_its_header() {
        let (_dir, path) = temp("empty");
        std::fs::write(&path, "").unwrap();
        let (mut log, rows) = CsvLog::<Row>::open(&path).unwrap();
        assert!(rows.is_empty());
        log.append(&row(1)).unwrap();
        drop(log);
        assert_eq!(
            std::fs::read_to_string(&path).unwrap(),
            "name,n,ms\nr1,1,1.5\n"
        );
    }

    #[test]
    fn a_foreign_file_is_refused_not_overwritten() {
        let (_other_dir, other) = temp("other-columns");
        std::fs::write(&other, "a,b\n1,2\n").unwrap();
        let e = CsvLog::<Row>::open(&other).err().unwrap().to_string();
        assert!(e.contains("name,n,ms"), "{e}");
        let (_dir, path) = temp("foreign");
        let text = "name,n,ms\nr1,one,1.5\nr2,2,3.0\n";
        std::fs::write(&path, text).unwrap();
        let e = CsvLog::<Row>::open(&path).err().unwrap().to_string();
        assert!(e.contains("start a new run"), "{e}");
        assert_eq!(std::fs::read_to_string(&path).unwrap(), text);
    }
}
