//! The tiles under a real scheduler: a single-node Slurm from Debian's packages (slurm-wlm,
//! munge; deploy/slurm/single-node.sh starts slurmctld and slurmd on localhost as root) runs
//! deploy/slurm/tiles.sbatch as a job array; the merge of its tiles is byte for byte the merge
//! of `tiles run --jobs 2`. Without the packages (or root) the test says so and passes, unless
//! CI=true, where it fails: .ci/run installs them.

use crate::common;

use common::{expect_code, meshslim};
use std::path::{Path, PathBuf};
use std::process::Command;

/// Stops the single node however the test ends.
struct Node(PathBuf);

impl Drop for Node {
    fn drop(&mut self) {
        let _ = Command::new("bash")
            .arg(script())
            .args(["stop".as_ref(), self.0.as_os_str()])
            .status();
    }
}

fn script() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("deploy/slurm/single-node.sh")
}

fn have(cmd: &str) -> bool {
    Command::new("sh")
        .args(["-c", &format!("command -v {cmd}")])
        .output()
        .is_ok_and(|o| o.status.success())
}

#[test]
fn a_slurm_array_writes_the_bytes_tiles_run_writes() {
    let root = Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| o.stdout.trim_ascii() == b"0");
    let missing: Vec<&str> = ["slurmctld", "slurmd", "sbatch", "munged"]
        .into_iter()
        .filter(|c| !have(c))
        .collect();
    if !missing.is_empty() || !root {
        let why = format!(
            "needs root and slurm-wlm + munge (missing: {missing:?}, root: {root}); \
             apt-get install -y --no-install-recommends slurm-wlm munge"
        );
        let ci = std::env::var("CI").is_ok_and(|v| v == "true");
        assert!(!ci, "CI=true but the Slurm test cannot run: {why}");
        eprintln!("note: Slurm test skipped: {why}");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path();
    let mut m = meshslim::mesh::torus(1.0, 0.3, 200, 80);
    meshslim::mesh::add_noise(&mut m, 0.002, 3);
    meshslim::io::write(&p.join("scan.ply"), &m).unwrap();
    for d in ["local", "slurm"] {
        let o = meshslim(
            &[
                "tiles", "split", "scan.ply", d, "--tiles", "4", "--ratio", "0.05",
            ],
            p,
        );
        expect_code(&o, 0);
    }
    expect_code(&meshslim(&["tiles", "run", "local", "--jobs", "2"], p), 0);
    expect_code(&meshslim(&["tiles", "merge", "local", "local.ply"], p), 0);

    let state = p.join("slurm-state");
    let o = Command::new("bash")
        .arg(script())
        .args(["start".as_ref(), state.as_os_str()])
        .output()
        .unwrap();
    let node = Node(state.clone());
    expect_code(&o, 0);
    let o = Command::new("sbatch")
        .args(["--array=0-3", "--wait", "-o"])
        .arg(state.join("log/%A_%a.log"))
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("deploy/slurm/tiles.sbatch"))
        .arg(p.join("slurm"))
        .env("SLURM_CONF", state.join("slurm.conf"))
        .env("MESHSLIM", env!("CARGO_BIN_EXE_meshslim"))
        .current_dir(p)
        .output()
        .unwrap();
    if !o.status.success() {
        let logs: String = std::fs::read_dir(state.join("log"))
            .into_iter()
            .flatten()
            .flatten()
            .map(|e| {
                let text = std::fs::read_to_string(e.path()).unwrap_or_default();
                let tail: Vec<&str> = text.lines().rev().take(20).collect();
                format!("==> {} <==\n{}\n", e.path().display(), tail.join("\n"))
            })
            .collect();
        panic!(
            "sbatch failed: {}\n{}\n{logs}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        );
    }
    drop(node);
    expect_code(&meshslim(&["tiles", "merge", "slurm", "slurm.ply"], p), 0);
    for i in 0..4 {
        let f = format!("tile-{i:04}.out.ply");
        assert_eq!(
            std::fs::read(p.join("local").join(&f)).unwrap(),
            std::fs::read(p.join("slurm").join(&f)).unwrap(),
            "{f}"
        );
    }
    let (a, b) = (
        std::fs::read(p.join("local.ply")).unwrap(),
        std::fs::read(p.join("slurm.ply")).unwrap(),
    );
    assert!(!a.is_empty());
    assert_eq!(a, b, "the Slurm array's merge differs from tiles run's");
}
