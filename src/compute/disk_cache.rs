//! The compiled pipelines kept on disk between processes: wgpu's `PipelineCache` (Vulkan's
//! `VkPipelineCache`, lavapipe included) in the user's cache folder, one file per meshslim
//! version, shader set and adapter. A missing, stale or corrupt file is ignored and written
//! anew, never an error: the cache only saves the driver's compile.

use std::path::{Path, PathBuf};

/// The first bytes of a cache file, then its format version.
const MAGIC: &[u8; 8] = b"MSLPIPE\0";
const FORMAT: u32 = 1;
/// Magic, format, payload length, payload hash.
const HEADER: usize = 8 + 4 + 8 + 8;

/// How a device's pipelines were found, for the report.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CacheStatus {
    /// Made from a valid file on disk.
    Hit,
    /// No valid file: compiled, and the file written.
    Miss,
    /// The adapter keeps no pipeline cache (not Vulkan, or without the feature), or the user
    /// has no cache folder.
    Unsupported,
}

impl std::fmt::Display for CacheStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            CacheStatus::Hit => "hit",
            CacheStatus::Miss => "miss",
            CacheStatus::Unsupported => "unsupported",
        })
    }
}

/// FNV-1a over `bytes`: a check that the payload is what was written (wgpu reserves a hash in
/// its own header but does not check it).
pub(crate) fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// The folder cache files go in: `MESHSLIM_CACHE_DIR`, else the platform's cache folder
/// (`$XDG_CACHE_HOME` or `~/.cache` on Linux) under `meshslim/`.
pub fn cache_dir() -> Option<PathBuf> {
    match std::env::var_os("MESHSLIM_CACHE_DIR") {
        Some(d) if !d.is_empty() => Some(PathBuf::from(d)),
        _ => dirs::cache_dir().map(|d| d.join("meshslim")),
    }
}

/// The cache file of an adapter (`key`, wgpu's `pipeline_cache_key`) for this build's shaders.
pub fn cache_file(dir: &Path, key: &str) -> PathBuf {
    let shaders = crate::compute::shaders::SOURCES
        .iter()
        .fold(0u64, |h, s| h.rotate_left(5) ^ fnv1a(s.source().as_bytes()));
    dir.join(format!(
        "{key}-meshslim-{}-{shaders:016x}.bin",
        env!("CARGO_PKG_VERSION")
    ))
}

/// The payload of a cache file, or `None` when it is missing, short, of another format, or
/// does not match its hash.
pub fn read(path: &Path) -> Option<Vec<u8>> {
    let bytes = std::fs::read(path).ok()?;
    decode(&bytes).map(<[u8]>::to_vec)
}

fn decode(bytes: &[u8]) -> Option<&[u8]> {
    let header = bytes.get(..HEADER)?;
    let word = |at: usize| u64::from_le_bytes(header[at..at + 8].try_into().unwrap_or([0; 8]));
    let format = u32::from_le_bytes(header[8..12].try_into().ok()?);
    let payload = &bytes[HEADER..];
    let ok = &header[..8] == MAGIC
        && format == FORMAT
        && word(12) == payload.len() as u64
        && word(20) == fnv1a(payload);
    ok.then_some(payload)
}

/// Writes `payload` to `path` through a temporary file and a rename, so a reader never sees
/// half a file; a failure is ignored (the next process compiles again).
pub fn write(path: &Path, payload: &[u8]) {
    let mut bytes = Vec::with_capacity(HEADER + payload.len());
    bytes.extend_from_slice(MAGIC);
    bytes.extend_from_slice(&FORMAT.to_le_bytes());
    bytes.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    bytes.extend_from_slice(&fnv1a(payload).to_le_bytes());
    bytes.extend_from_slice(payload);
    let Some(dir) = path.parent() else { return };
    if std::fs::create_dir_all(dir).is_err() {
        return;
    }
    let Ok(mut tmp) = tempfile::NamedTempFile::new_in(dir) else {
        return;
    };
    if std::io::Write::write_all(&mut tmp, &bytes).is_ok() {
        let _ = tmp.persist(path);
    }
}

/// A device's pipeline cache and the file it came from and goes back to.
pub struct DiskCache {
    pub cache: wgpu::PipelineCache,
    path: PathBuf,
    pub status: CacheStatus,
}

impl DiskCache {
    /// The cache of `device` (made on the adapter `info`) in the folder `dir`, seeded from
    /// its file when that is valid; `None` when the device cannot keep one.
    pub fn open(device: &wgpu::Device, info: &wgpu::AdapterInfo, dir: &Path) -> Option<DiskCache> {
        if !device.features().contains(wgpu::Features::PIPELINE_CACHE) {
            return None;
        }
        let key = wgpu::util::pipeline_cache_key(info)?;
        let path = cache_file(dir, &key);
        let data = read(&path);
        // SAFETY: wgpu asks that `data` come from `PipelineCache::get_data` of an adapter with
        // the same `pipeline_cache_key`. The file is named by that key and this build's
        // shaders, and its payload is taken only when its length and hash match what
        // `write` stored from `get_data`; wgpu then checks its own header (adapter, driver,
        // version), and `fallback` makes an empty cache of anything it does not accept.
        let cache = unsafe {
            device.create_pipeline_cache(&wgpu::PipelineCacheDescriptor {
                label: Some("meshslim.pipeline_cache"),
                data: data.as_deref(),
                fallback: true,
            })
        };
        let status = if data.is_some() {
            CacheStatus::Hit
        } else {
            CacheStatus::Miss
        };
        Some(DiskCache {
            cache,
            path,
            status,
        })
    }

    /// The file the cache is read from and written to.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Writes the cache back when it was not read from disk (a hit leaves the file as it is).
    pub fn save(&self) {
        if self.status == CacheStatus::Miss
            && let Some(data) = self.cache.get_data()
        {
            write(&self.path, &data);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_written_cache_reads_back_and_a_damaged_one_does_not() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sub").join("c.bin");
        assert_eq!(read(&path), None, "missing");
        write(&path, b"pipelines");
        assert_eq!(read(&path).as_deref(), Some(&b"pipelines"[..]));
        let mut bytes = std::fs::read(&path).unwrap();
        let last = bytes.len() - 1;
        bytes[last] ^= 1;
        std::fs::write(&path, &bytes).unwrap();
        assert_eq!(read(&path), None, "a flipped payload bit");
        std::fs::write(&path, &bytes[..HEADER - 1]).unwrap();
        assert_eq!(read(&path), None, "short of its header");
        std::fs::write(&path, b"").unwrap();
        assert_eq!(read(&path), None, "empty");
    }

    #[test]
    fn the_file_is_named_by_adapter_version_and_shaders() {
        let name = cache_file(Path::new("/c"), "wgpu_pipeline_cache_vulkan_1_2");
        let name = name.to_string_lossy();
        assert!(name.starts_with("/c/wgpu_pipeline_cache_vulkan_1_2-meshslim-"));
        assert!(name.contains(env!("CARGO_PKG_VERSION")));
    }
}
