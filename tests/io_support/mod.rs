//! Helpers of the file-format tests (tests/io.rs and tests/io_hostile.rs): temporary folders,
//! a counting allocator that bounds what a header may make a reader allocate, a mesh with every
//! attribute, and error-message checks.
#![allow(dead_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::path::{Path, PathBuf};

use meshslim::io;
use meshslim::{Material, Mesh};

pub fn tmp() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

/// Counts the bytes each thread has allocated and not freed, and the peak since the last reset,
/// so a test can show that a header's claims are not allocated before the data is there.
struct CountingAlloc;

thread_local! {
    static LIVE: Cell<isize> = const { Cell::new(0) };
    static PEAK: Cell<isize> = const { Cell::new(0) };
}

// SAFETY: every call forwards to `System` with the caller's own layout and pointer, so the
// allocator contract is System's; the bookkeeping only touches const-initialised thread-locals,
// which never allocate (`try_with` ignores threads being torn down).
unsafe impl GlobalAlloc for CountingAlloc {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = LIVE.try_with(|l| {
            l.set(l.get() + layout.size() as isize);
            let _ = PEAK.try_with(|p| p.set(p.get().max(l.get())));
        });
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        let _ = LIVE.try_with(|l| l.set(l.get() - layout.size() as isize));
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOC: CountingAlloc = CountingAlloc;

/// Peak bytes this thread held while running `f`, above what it held before.
pub fn peak_alloc<T>(f: impl FnOnce() -> T) -> (T, usize) {
    let base = LIVE.with(Cell::get);
    PEAK.with(|p| p.set(base));
    let out = f();
    (out, (PEAK.with(Cell::get) - base).max(0) as usize)
}

/// A small closed mesh (an octahedron) with every attribute, two groups and two materials,
/// faces ordered by group then material (the order glTF writes them in).
pub fn full_mesh() -> Mesh {
    let positions = vec![
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
    ];
    let triangles = vec![
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    let mut m = Mesh::new(positions, triangles);
    m.normals = Some(m.positions.clone());
    m.uvs = Some(vec![
        [0.1, 0.2],
        [0.3, 0.4],
        [0.5, 0.6],
        [0.7, 0.8],
        [0.9, 1.0],
        [0.123_456_79, 1e-7],
    ]);
    m.colors = Some(vec![
        [1.0, 0.0, 0.0, 1.0],
        [0.0, 1.0, 0.0, 1.0],
        [0.0, 0.0, 1.0, 1.0],
        [0.5, 0.25, 0.125, 1.0],
        [1.0, 1.0, 1.0, 1.0],
        [0.3, 0.6, 0.9, 1.0],
    ]);
    m.groups = vec!["top".into(), "bottom".into()];
    m.face_groups = Some(vec![0, 0, 0, 0, 1, 1, 1, 1]);
    m.materials = vec![Material::named("red"), Material::named("blue")];
    m.face_materials = Some(vec![0, 0, 1, 1, 0, 0, 1, 1]);
    m.material_libs = vec!["scene.mtl".into()];
    m
}

pub fn geometry_only(m: &Mesh) -> Mesh {
    Mesh::new(m.positions.clone(), m.triangles.clone())
}

pub fn err_text<T: std::fmt::Debug>(r: meshslim::Result<T>) -> String {
    match r {
        Ok(v) => panic!("expected an error, got {v:?}"),
        Err(e) => e.to_string(),
    }
}

/// Asserts that reading `path` fails with a message naming the file and containing `loc`.
pub fn assert_read_err(path: &Path, loc: &str) -> String {
    let msg = err_text(io::read(path));
    let name = path.file_name().unwrap().to_string_lossy();
    assert!(
        msg.contains(&*name),
        "message {msg:?} does not name the file {name}"
    );
    assert!(
        msg.contains(loc),
        "message {msg:?} does not contain {loc:?}"
    );
    msg
}

pub fn write_text(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}
