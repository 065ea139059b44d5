//! The command line's errors: a usage mistake (exit code 2, as clap's own) and the library's
//! errors passed on as messages.

/// A mistake in how the command was called: reported like clap's own, with exit code 2.
#[derive(Debug)]
pub struct UsageError(pub String);

impl std::fmt::Display for UsageError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for UsageError {}

/// The library's errors carry the file and the cause in their message already; passing them on
/// as messages keeps `{:#}` from printing the cause a second time.
pub(super) fn lib(e: crate::Error) -> anyhow::Error {
    anyhow::Error::msg(e.to_string())
}
