//! `smithwalk plot`: every figure of a run with models is written, decodes as a PNG of the
//! expected size with more than background in it, and `index.html` links exactly the figures.

use std::collections::BTreeSet;

use smithwalk::setup::config::Config;
use smithwalk::setup::config::Model;

#[test]
fn plot_writes_every_figure_and_an_index_that_shows_them() {
    let toml = "paths = 20000\nseed = 3\n[surface]\nalpha = [0.3, 0.8]\n[[material]]\nkind = \"conductor\"\n[[material]]\nkind = \"dielectric\"\neta = 1.5\n[incident]\ntheta_deg = [0, 45]\n[detector]\ncos_theta_bins = 8\nphi_bins = 16\nmax_order = 3\n";
    let config = Config::parse(toml).unwrap();
    let sim = smithwalk::simulate(&config, Some(2), false).unwrap();
    let dir = tempfile::tempdir().unwrap();
    smithwalk::write_outputs(&sim, &config, dir.path()).unwrap();
    smithwalk::analysis::compare::compare(
        dir.path(),
        &[Model::Single, Model::WangCorrelated],
        Some(20000),
        Some(2),
        None,
    )
    .unwrap();
    let written = smithwalk::exports::plot::plot(dir.path()).unwrap();
    let names: BTreeSet<String> =
        written.iter().map(|p| p.file_name().unwrap().to_string_lossy().into_owned()).collect();

    // 8 cases: 4 conductor (R) and 4 dielectric (R and T) heat maps; 4 groups of lobes
    // (alpha x material), the dielectric ones in R and T; two albedo figures; the index.
    let mut expected = BTreeSet::new();
    for case in sim.cases.iter() {
        expected.insert(format!("heat_case{}_R.png", case.index));
        if case.material.transmits() {
            expected.insert(format!("heat_case{}_T.png", case.index));
        }
    }
    for (g, transmits) in [(0, false), (1, true), (2, false), (3, true)] {
        expected.insert(format!("lobes_g{g}_R.png"));
        if transmits {
            expected.insert(format!("lobes_g{g}_T.png"));
        }
    }
    expected.extend(["albedo_vs_theta.png", "albedo_vs_alpha.png", "index.html"].map(String::from));
    assert_eq!(names, expected);

    for name in names.iter().filter(|n| n.ends_with(".png")) {
        let image = image::open(dir.path().join(name)).unwrap().to_rgb8();
        assert!(image.width() >= 300 && image.height() >= 250, "{name}: {:?}", image.dimensions());
        let colours: BTreeSet<[u8; 3]> = image.pixels().map(|p| p.0).collect();
        assert!(colours.len() > 20, "{name}: only {} colours", colours.len());
    }
    // The lobe figures have 3 order rows + all orders, and a column per incident angle.
    let lobes = image::open(dir.path().join("lobes_g0_R.png")).unwrap();
    assert_eq!((lobes.width(), lobes.height()), (2 * 280, 40 + 4 * 210));

    let html = std::fs::read_to_string(dir.path().join("index.html")).unwrap();
    let linked: BTreeSet<String> = html.split('"').filter(|s| s.ends_with(".png")).map(String::from).collect();
    let pngs: BTreeSet<String> = expected.iter().filter(|n| n.ends_with(".png")).cloned().collect();
    assert_eq!(linked, pngs);
    assert!(html.contains("single, wang-correlated"), "the index names the models");
}
