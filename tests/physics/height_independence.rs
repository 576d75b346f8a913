//! Bookkeeping only: the `height` setting is a label in the optical-depth walk. The walk never
//! receives the height law (it runs in optical depth `-ln C1(h)`, docs/theory.md §2.4), so this
//! test cannot fail for a physical reason; what it can catch is a height setting that leaks
//! into the seeding, the case order or the numbers written (same seed, same photons: every
//! energy, standard error and count of lobes.csv and summary.csv agrees to the bit; only the
//! `height` column differs).
//!
//! The physical claim, that uniform and Gaussian heights give the same lobes, is measured in
//! height_walk.rs against a reference walk that samples actual heights. (The height process
//! itself is tested against its closed forms in height_process.rs.)

use smithwalk::setup::config::Config;

fn csv_without_height(height: &str, file: &str) -> String {
    let toml = format!(
        "paths = 50_000\nseed = 4\n[surface]\nalpha = [0.5, [0.7, 0.3]]\nheight = \"{height}\"\nsmith = [\"exact\", \"symmetric\"]\n[[material]]\nkind = \"conductor\"\n[[material]]\nkind = \"dielectric\"\neta = 1.5\n[incident]\ntheta_deg = [0, 45]\n[detector]\ncos_theta_bins = 8\nphi_bins = 8\nmax_order = 4\n"
    );
    let config = Config::parse(&toml).unwrap();
    let sim = smithwalk::simulate(&config, Some(2), false).unwrap();
    let dir = tempfile::tempdir().unwrap();
    smithwalk::write_outputs(&sim, &config, dir.path()).unwrap();
    let text = std::fs::read_to_string(dir.path().join(file)).unwrap();
    assert!(text.contains(&format!(",{height},")), "the height law is recorded");
    text.replace(&format!(",{height},"), ",HEIGHT,")
}

#[test]
fn bookkeeping_the_height_label_changes_no_number_written() {
    for file in ["lobes.csv", "summary.csv"] {
        assert!(csv_without_height("uniform", file) == csv_without_height("gaussian", file), "{file} differs");
    }
}
