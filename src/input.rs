//! Files read within a size bound: a config, a table or a run directory's file that is larger
//! than its bound, or endless (`/dev/zero`, a FIFO that never closes), is refused with one line
//! once the bound is passed, instead of filling memory until the process is killed. The bounds
//! are listed in docs/reliability.md ("Limits").

use std::fs::File;
use std::io::{self, Read};
use std::path::Path;

/// The largest configuration file read (`smithwalk run`, `smithwalk lut`, a Python dict's
/// TOML): 16 MiB, a thousand times a sweep of a thousand values per list.
pub const MAX_CONFIG_BYTES: u64 = 16 << 20;

/// The largest table a user hands in (`compare --external`, `compare --albedo-table`): 1 GiB.
/// A table that holds a model in a run's bins may also be as large as four times the run's
/// `lobes.csv` ([`bins_table_limit`]).
pub const MAX_TABLE_BYTES: u64 = 1 << 30;

/// The largest `run.json`: 2 GiB. It holds about 1 KB per case (measured: 970 bytes per case
/// with a 100-character material name, one channel), so the 10^6 cases a run may have fit.
pub const MAX_RUN_JSON_BYTES: u64 = 2 << 30;

/// The bound of a table in the bins of a run whose `lobes.csv` has `lobes_bytes` bytes
/// (`--external`, `models.csv`): [`MAX_TABLE_BYTES`] or four times `lobes.csv`, whichever is
/// larger, so that a model written with more digits than the run still fits.
pub fn bins_table_limit(lobes_bytes: u64) -> u64 {
    MAX_TABLE_BYTES.max(lobes_bytes.saturating_mul(4))
}

/// A reader that yields at most `limit` bytes and fails, naming the limit, when there are more.
pub struct Bounded<R> {
    inner: io::Take<R>,
    limit: u64,
}

impl<R: Read> Bounded<R> {
    /// Reads `inner` up to `limit` bytes.
    pub fn new(inner: R, limit: u64) -> Self {
        Self { inner: inner.take(limit.saturating_add(1)), limit }
    }
}

impl<R: Read> Read for Bounded<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(buf)?;
        // The inner reader stops one byte past the limit: having read it, the input is too large.
        if self.inner.limit() == 0 {
            return Err(too_large(self.limit));
        }
        Ok(n)
    }
}

/// The error of an input larger than `limit` bytes.
fn too_large(limit: u64) -> io::Error {
    io::Error::new(io::ErrorKind::FileTooLarge, format!("larger than {}, the most allowed", size_text(limit)))
}

/// `bytes` in binary units, e.g. `16 MiB`, exact when it is a whole number of them.
pub fn size_text(bytes: u64) -> String {
    match [(30, "GiB"), (20, "MiB"), (10, "KiB")].into_iter().find(|(shift, _)| bytes >> shift > 0) {
        Some((shift, unit)) if bytes.is_multiple_of(1 << shift) => format!("{} {unit}", bytes >> shift),
        Some((shift, unit)) => format!("{:.1} {unit}", bytes as f64 / (1u64 << shift) as f64),
        None => format!("{bytes} bytes"),
    }
}

/// Opens `path` for reading at most `limit` bytes.
pub fn open(path: &Path, limit: u64) -> io::Result<Bounded<File>> {
    Ok(Bounded::new(File::open(path)?, limit))
}

/// The bytes of `path`, at most `limit` of them.
pub fn read(path: &Path, limit: u64) -> io::Result<Vec<u8>> {
    let mut bytes = Vec::new();
    open(path, limit)?.read_to_end(&mut bytes)?;
    Ok(bytes)
}

/// The text of `path` (UTF-8), at most `limit` bytes of it. Bytes that are not UTF-8 are
/// refused with the place of the first: its byte offset, line and column.
pub fn read_to_string(path: &Path, limit: u64) -> io::Result<String> {
    String::from_utf8(read(path, limit)?).map_err(|e| not_utf8(e.as_bytes(), e.utf8_error()))
}

/// The error of `bytes` that are not UTF-8 from `e.valid_up_to()` on.
fn not_utf8(bytes: &[u8], e: std::str::Utf8Error) -> io::Error {
    let offset = e.valid_up_to();
    // What precedes the first bad byte is UTF-8: its lines and characters are the user's.
    let valid = std::str::from_utf8(&bytes[..offset]).unwrap_or_default();
    let line = valid.matches('\n').count() + 1;
    let column = valid.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    let what = match e.error_len() {
        Some(_) => format!("the byte 0x{:02X}", bytes[offset]),
        None => "the end of the file, inside a character,".to_string(),
    };
    io::Error::new(
        io::ErrorKind::InvalidData,
        format!(
            "{what} at line {line}, column {column} (byte offset {offset}) is not UTF-8: the file must be UTF-8 text"
        ),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_input_of_the_limit_is_read_and_one_byte_more_is_refused() {
        let mut exact = Vec::new();
        Bounded::new(&[7u8; 10][..], 10).read_to_end(&mut exact).unwrap();
        assert_eq!(exact, [7u8; 10]);
        let mut longer = Vec::new();
        let e = Bounded::new(&[7u8; 11][..], 10).read_to_end(&mut longer).unwrap_err();
        assert_eq!(e.to_string(), "larger than 10 bytes, the most allowed");
        // An endless input stops at the limit.
        let e = Bounded::new(io::repeat(0), MAX_CONFIG_BYTES).read_to_end(&mut Vec::new()).unwrap_err();
        assert_eq!(e.to_string(), "larger than 16 MiB, the most allowed");
    }

    #[test]
    fn text_that_is_not_utf8_is_refused_with_the_place_of_its_first_bad_byte() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("latin1.toml");
        std::fs::write(&path, b"paths = 1\n# \xC3\xA9t\xE9\n").unwrap();
        let e = read_to_string(&path, MAX_CONFIG_BYTES).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::InvalidData);
        assert_eq!(
            e.to_string(),
            "the byte 0xE9 at line 2, column 5 (byte offset 15) is not UTF-8: the file must be UTF-8 text"
        );
        std::fs::write(&path, b"a = \xC3").unwrap();
        let e = read_to_string(&path, MAX_CONFIG_BYTES).unwrap_err().to_string();
        assert!(e.starts_with("the end of the file, inside a character, at line 1, column 5 (byte offset 4)"), "{e}");
    }

    #[test]
    fn sizes_read_in_binary_units() {
        assert_eq!(size_text(MAX_TABLE_BYTES), "1 GiB");
        assert_eq!(size_text(3 << 19), "1.5 MiB");
        assert_eq!(size_text(1023), "1023 bytes");
    }
}
