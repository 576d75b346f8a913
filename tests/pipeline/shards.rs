//! Runs split into shards and merged give exactly the unsplit run's tables (the accumulators
//! are integers), and merge refuses incomplete, duplicated or mismatched shard sets.

use crate::common;

use std::path::{Path, PathBuf};

use common::tables;

use smithwalk::engine::run::Shard;
use smithwalk::engine::shard::{merge, write_shard};
use smithwalk::setup::config::Config;

const CONFIG: &str = r#"
paths = 70_000
seed = 31
[surface]
alpha = [0.4, [1.0, 0.1]]
[[material]]
kind = "dielectric"
eta = 1.5
[[material]]
kind = "conductor"
fresnel = "schlick"
f0 = 0.8
[incident]
theta_deg = [0, 75]
[detector]
cos_theta_bins = 8
phi_bins = 16
max_order = 3
"#;

fn shard_dirs(config: &Config, count: u64, root: &Path) -> Vec<PathBuf> {
    (0..count)
        .map(|index| {
            let dir = root.join(format!("shard{index}"));
            std::fs::create_dir_all(&dir).unwrap();
            // Shards may run with any thread count.
            let threads = 1 + (index as usize % 2);
            let shard = Shard { index, count };
            let sim = smithwalk::simulate_shard(config, shard, Some(threads), false).unwrap();
            write_shard(&sim, config, shard, &dir).unwrap();
            dir
        })
        .collect()
}

#[test]
fn merged_shards_equal_the_unsplit_run() {
    let config = Config::parse(CONFIG).unwrap();
    let root = tempfile::tempdir().unwrap();
    let whole = root.path().join("whole");
    std::fs::create_dir_all(&whole).unwrap();
    let sim = smithwalk::simulate(&config, Some(2), false).unwrap();
    smithwalk::write_outputs(&sim, &config, &whole).unwrap();
    // 70 000 photons are 5 chunks: 4 shards get 2, 1, 1, 1 chunks; 7 shards leave two empty.
    for count in [4, 7] {
        let dirs = shard_dirs(&config, count, &root.path().join(format!("n{count}")));
        let (merged_config, merged) = merge(&dirs).unwrap();
        assert_eq!(merged_config, config);
        let out = root.path().join(format!("merged{count}"));
        std::fs::create_dir_all(&out).unwrap();
        smithwalk::write_outputs(&merged, &merged_config, &out).unwrap();
        assert!(tables(&whole) == tables(&out), "{count} shards: merged tables differ from the unsplit run");
    }
}

#[test]
fn merge_rejects_bad_shard_sets() {
    let config = Config::parse(CONFIG).unwrap();
    let root = tempfile::tempdir().unwrap();
    let dirs = shard_dirs(&config, 3, root.path());
    let err = |dirs: &[PathBuf]| merge(dirs).expect_err("merge must fail").to_string();
    assert!(err(&dirs[..2]).contains("missing shards: 2/3"));
    assert!(err(&[dirs[0].clone(), dirs[0].clone(), dirs[1].clone()]).contains("given twice"));
    let other = Config { seed: 32, ..config.clone() };
    let foreign = shard_dirs(&other, 3, &root.path().join("other"));
    assert!(err(&[dirs[0].clone(), dirs[1].clone(), foreign[2].clone()]).contains("different config"));
    std::fs::write(dirs[1].join("shard.bin"), b"not a shard").unwrap();
    assert!(err(&dirs).contains("not a smithwalk shard file"));
}
