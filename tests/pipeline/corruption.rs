//! Damaged shard and checkpoint files are refused: every byte of a small `shard.bin` and
//! `checkpoint.bin` is flipped (xor 0x01 and xor 0xff, one byte at a time), and each damaged
//! file must be refused by `merge` or `--resume`, or give tables byte-identical to the intact
//! file's. With the SHA-256 seal every one is refused; the test asserts the weaker property the
//! user relies on (no silently different table).

use std::path::Path;

use smithwalk::engine::checkpoint::{self, CHECKPOINT_FILE, Checkpointer};
use smithwalk::engine::run::{Estimator, Shard};
use smithwalk::engine::shard::{SHARD_FILE, merge, write_shard};
use smithwalk::io::output::{lobes_csv, summary_csv};
use smithwalk::setup::config::Config;
use smithwalk::{RunOptions, Simulation};

/// Two cases of a dielectric (both hemispheres), a tiny grid, orders folded at 2:
/// shard files of about 3 kB.
const CONFIG: &str = r#"
paths = 40_000
seed = 5
[surface]
alpha = 0.5
[[material]]
kind = "dielectric"
eta = 1.5
[incident]
theta_deg = [30, 70]
[detector]
cos_theta_bins = 2
phi_bins = 2
max_order = 2
"#;

fn tables(sim: &Simulation) -> (Vec<u8>, Vec<u8>) {
    (lobes_csv(sim).unwrap(), summary_csv(sim).unwrap())
}

/// Flips every byte of `file` in turn (xor 0x01 and 0xff), calls `read` on the damaged
/// directory, and returns how many flips were refused; panics if one gave other tables.
fn flip_every_byte(file: &Path, expected: &(Vec<u8>, Vec<u8>), read: impl Fn() -> anyhow::Result<Simulation>) -> usize {
    let intact = std::fs::read(file).unwrap();
    let mut refused = 0;
    for i in 0..intact.len() {
        for flip in [0x01u8, 0xff] {
            let mut bytes = intact.clone();
            bytes[i] ^= flip;
            std::fs::write(file, &bytes).unwrap();
            match read() {
                Err(e) => {
                    assert!(!format!("{e:#}").contains('\n'), "byte {i}: a multi-line error: {e:#}");
                    refused += 1;
                }
                Ok(sim) => assert!(tables(&sim) == *expected, "byte {i} xor {flip:#04x} gave different tables"),
            }
        }
    }
    std::fs::write(file, &intact).unwrap();
    refused
}

#[test]
fn every_byte_flip_of_a_shard_is_refused_or_harmless() {
    let config = Config::parse(CONFIG).unwrap();
    let root = tempfile::tempdir().unwrap();
    let dirs: Vec<_> = (0..2)
        .map(|index| {
            let dir = root.path().join(format!("shard{index}"));
            std::fs::create_dir_all(&dir).unwrap();
            let shard = Shard { index, count: 2 };
            let sim = smithwalk::simulate_shard(&config, shard, Some(1), false).unwrap();
            write_shard(&sim, &config, shard, &dir).unwrap();
            dir
        })
        .collect();
    let expected = tables(&merge(&dirs).unwrap().1);
    let file = dirs[0].join(SHARD_FILE);
    let len = std::fs::read(&file).unwrap().len();
    let refused = flip_every_byte(&file, &expected, || merge(&dirs).map(|(_, sim)| sim));
    // The seal makes every flip detectable: all 2 x len are refused.
    assert_eq!(refused, 2 * len, "{refused} of {} flips of a {len}-byte shard refused", 2 * len);
}

#[test]
fn a_shard_claiming_an_index_beyond_its_count_is_refused() {
    let config = Config::parse(CONFIG).unwrap();
    let root = tempfile::tempdir().unwrap();
    let sim = smithwalk::simulate_shard(&config, Shard { index: 0, count: 2 }, Some(1), false).unwrap();
    // A well-sealed file that says it is share 5 of 2 (once an index out of bounds in merge).
    write_shard(&sim, &config, Shard { index: 5, count: 2 }, root.path()).unwrap();
    let e = merge(&[root.path().to_path_buf()]).expect_err("refused");
    assert!(format!("{e:#}").contains("5/2"), "{e:#}");
    // A file without the seal (format 1, or not a shard at all) is refused by name.
    std::fs::write(root.path().join(SHARD_FILE), b"not a shard").unwrap();
    let e = merge(&[root.path().to_path_buf()]).expect_err("refused");
    assert!(format!("{e:#}").contains("is not a smithwalk shard file"), "{e:#}");
}

#[test]
fn every_byte_flip_of_a_checkpoint_is_refused_or_harmless() {
    // Two rounds of chunks per case, so the checkpoint is taken in the middle of the run.
    let config = Config::parse(&CONFIG.replace("40_000", "600_000")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let options = RunOptions {
        estimator: Estimator::Walk,
        shard: Shard::WHOLE,
        threads: Some(2),
        show_progress: false,
        max_memory: None,
    };
    let expected = tables(&smithwalk::simulate(&config, Some(2), false).unwrap());
    let mut checkpoints = Checkpointer::new(dir.path(), std::time::Duration::ZERO, &config, Shard::WHOLE).unwrap();
    // A run killed after its first checkpoint: the hook stops it.
    let stopped = smithwalk::simulate_from(&config, &options, None, &mut |done, current, later| {
        checkpoints.after_round(done, current, later)?;
        anyhow::bail!("killed")
    });
    assert!(stopped.is_err());
    let file = dir.path().join(CHECKPOINT_FILE);
    let resume = || {
        let states = checkpoint::load(dir.path(), &config, Shard::WHOLE)?;
        smithwalk::simulate_from(&config, &options, states, &mut |_, _, _| Ok(()))
    };
    // The intact checkpoint resumes to the uninterrupted run's tables.
    assert!(tables(&resume().unwrap()) == expected);
    let len = std::fs::read(&file).unwrap().len();
    let refused = flip_every_byte(&file, &expected, resume);
    assert_eq!(refused, 2 * len, "{refused} of {} flips of a {len}-byte checkpoint refused", 2 * len);
}
