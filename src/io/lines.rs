//! Text formats read line by line, each line numbered for the errors that name it.

use std::borrow::Cow;
use std::io::BufRead;
use std::path::Path;

use crate::error::{Error, Location, Result};

/// A text file's lines, decoded lossily as UTF-8 and counted from 1.
pub(crate) struct Lines<'p, R> {
    r: R,
    path: &'p Path,
    buf: Vec<u8>,
    /// Lines read so far: at the end of the file, its line count.
    pub line_no: u64,
}

impl<'p, R: BufRead> Lines<'p, R> {
    /// Lines of `r`, whose read errors name `path`.
    pub fn new(r: R, path: &'p Path) -> Self {
        Lines {
            r,
            path,
            buf: Vec::new(),
            line_no: 0,
        }
    }

    /// The next line (with its line ending) and where it stands; `None` at the end of the file.
    pub fn next_line(&mut self) -> Result<Option<(Location, Cow<'_, str>)>> {
        self.buf.clear();
        let n = self
            .r
            .read_until(b'\n', &mut self.buf)
            .map_err(|e| Error::io(self.path, e))?;
        if n == 0 {
            return Ok(None);
        }
        self.line_no += 1;
        Ok(Some((
            Location::Line(self.line_no),
            String::from_utf8_lossy(&self.buf),
        )))
    }
}
