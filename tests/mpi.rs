//! Runs over MPI ranks (cargo feature `mpi`; needs OpenMPI's `mpirun`): `mpirun -np N
//! smithwalk run CONFIG` writes tables bit-identical to the plain run's, for any N, also when
//! every process is killed with SIGKILL and the job is run again with `--resume`.
//!
//! `cargo test --release --features mpi --test mpi` (as `.ci/run` does, as root). Cargo.toml
//! gives this target `required-features = ["mpi"]`: without the feature cargo does not build
//! it at all (rather than compiling it to zero tests that look like a pass), and
//! `--test mpi` alone says the feature is required.

mod common;

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use common::{smithwalk_quiet, tables};

/// Both facet kinds the walk treats differently (side by side, and with split branches), 13
/// chunks of photons: ranks get unequal shares.
const CONFIG: &str = r#"
paths = 200_000
seed = 11
[surface]
alpha = [0.3, 1.0]
[[material]]
kind = "conductor"
[[material]]
kind = "dielectric"
eta = 1.5
[incident]
theta_deg = [0, 70]
[detector]
cos_theta_bins = 8
phi_bins = 16
max_order = 4
"#;

/// `smithwalk ARGS` on `ranks` ranks, as root if need be (CI runs as root).
fn mpirun(ranks: usize, args: &[&str]) -> Command {
    let mut c = Command::new("mpirun");
    c.args(["--allow-run-as-root", "--oversubscribe", "-np", &ranks.to_string()])
        .arg(env!("CARGO_BIN_EXE_smithwalk"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    c
}

/// The plain run of `config` into `dir`.
fn reference(config: &str, dir: &Path) {
    assert!(smithwalk_quiet(&["run", config, "--out", dir.to_str().unwrap()]).status().unwrap().success());
}

/// Writes `text` as `name` into `root` and returns its path.
fn config_file(root: &Path, name: &str, text: &str) -> String {
    let path = root.join(name);
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_owned()
}

/// Names of what is in `dir`, sorted.
fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    names
}

#[test]
fn ranks_reproduce_the_plain_run_bit_for_bit() {
    let root = tempfile::tempdir().unwrap();
    let config = &config_file(root.path(), "ranks.toml", CONFIG);
    let plain = root.path().join("plain");
    reference(config, &plain);
    let cores = std::thread::available_parallelism().unwrap().get();
    for ranks in [2, 3] {
        let out = root.path().join(format!("np{ranks}"));
        let output =
            mpirun(ranks, &["run", config, "--out", out.to_str().unwrap()]).stdout(Stdio::piped()).output().unwrap();
        assert!(output.status.success(), "np {ranks}: {}", String::from_utf8_lossy(&output.stderr));
        // Without `--threads`, the ranks on one machine share its cores.
        let threads = format!(" on {} threads:", (cores / ranks).max(1) * ranks);
        let stdout = String::from_utf8_lossy(&output.stdout);
        assert!(stdout.contains(&threads), "np {ranks} on {cores} cores: expected {threads:?} in {stdout}");
        assert!(tables(&plain) == tables(&out), "np {ranks}: tables differ from the plain run");
        assert_eq!(entries(&out), ["lobes.csv", "run.json", "summary.csv"], "np {ranks}: left-overs");
    }
}

#[test]
fn bad_options_under_mpirun_stop_every_rank_and_write_nothing() {
    let root = tempfile::tempdir().unwrap();
    let config = &config_file(root.path(), "ranks.toml", CONFIG);
    let precision =
        &config_file(root.path(), "precision.toml", &format!("{CONFIG}[precision]\ntarget_rel_stderr = 0.01\n"));
    let cases: [(&[&str], &str); 2] = [
        (&["run", config, "--shard", "0/2"], "`--shard` = 0/2 is not allowed under mpirun"),
        (&["run", precision], "a `[precision]` target is not allowed under mpirun"),
    ];
    for (i, (args, message)) in cases.into_iter().enumerate() {
        let out = root.path().join(format!("bad{i}"));
        let output = mpirun(2, &[args, &["--out", out.to_str().unwrap()]].concat()).output().unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success(), "{args:?} succeeded");
        assert!(stderr.contains(message), "{args:?}: {stderr}");
        assert!(!out.exists(), "{args:?}: wrote {:?}", entries(&out));
    }
}

/// Child processes of `pid` (from /proc).
fn children(pid: u32) -> Vec<u32> {
    std::fs::read_dir("/proc")
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().to_str()?.parse::<u32>().ok())
        .filter(|p| {
            // `pid (comm) state ppid ...`; comm may hold spaces, so split after its `)`.
            std::fs::read_to_string(format!("/proc/{p}/stat"))
                .ok()
                .and_then(|s| s.rsplit_once(')').and_then(|(_, rest)| rest.split_whitespace().nth(1)?.parse().ok()))
                == Some(pid)
        })
        .collect()
}

/// SIGKILL to every rank of a job, then to its `mpirun`.
fn kill_job(mpirun: &mut Child) {
    for rank in children(mpirun.id()) {
        let _ = Command::new("kill").args(["-9", &rank.to_string()]).status();
    }
    let _ = mpirun.kill();
    mpirun.wait().unwrap();
}

#[test]
fn killed_jobs_resume_to_the_plain_run() {
    let root = tempfile::tempdir().unwrap();
    let config = &config_file(root.path(), "long.toml", &CONFIG.replace("paths = 200_000", "paths = 3_000_000"));
    let plain = root.path().join("plain");
    reference(config, &plain);

    let out = root.path().join("killed");
    let out_arg = out.to_str().unwrap();
    let args = ["run", config, "--threads", "1", "--out", out_arg, "--resume", "--checkpoint-seconds", "0.05"];
    let checkpoints = [out.join("rank-0-of-2/checkpoint.bin"), out.join("rank-1-of-2/checkpoint.bin")];
    // Kill moments from a fixed linear congruential sequence, each after both ranks checkpointed.
    let mut state: u64 = 777;
    for _ in 0..3 {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        let delay = Duration::from_millis(100 + (state >> 33) % 400);
        let mut job = mpirun(2, &args).spawn().unwrap();
        let start = Instant::now();
        while !checkpoints.iter().all(|c| c.exists()) && start.elapsed() < Duration::from_secs(60) {
            std::thread::sleep(Duration::from_millis(10));
        }
        std::thread::sleep(delay);
        assert!(job.try_wait().unwrap().is_none(), "the job ended before it was killed: make it longer");
        kill_job(&mut job);
        assert!(checkpoints.iter().all(|c| c.exists()), "a killed job left no checkpoint");
    }
    // What a kill in the middle of writing a checkpoint leaves behind.
    std::fs::write(out.join("rank-1-of-2/.tmpKilled"), b"half a checkpoint").unwrap();
    let output = mpirun(2, &args).output().unwrap();
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    assert!(tables(&plain) == tables(&out), "resumed job differs from the plain run");
    assert_eq!(entries(&out), ["lobes.csv", "run.json", "summary.csv"], "checkpoints left behind");
}
