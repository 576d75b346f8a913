//! `smithwalk plot`: every figure of a run with models is written and decodes with content;
//! `index.html` shows exactly the figures, each with a caption, the case columns that vary,
//! and the comparison read from compare.csv by column name; SVG output, `--out`, the channel of
//! RGB runs, and wide sweeps wrapped into a grid.

use std::collections::BTreeSet;
use std::path::Path;

use smithwalk::exports::plot::{Format, PlotOptions, plot};
use smithwalk::setup::config::{Config, Model};

fn run(toml: &str, dir: &Path) -> smithwalk::Simulation {
    let config = Config::parse(toml).unwrap();
    let sim = smithwalk::simulate(&config, Some(2), false).unwrap();
    smithwalk::write_outputs(&sim, &config, dir).unwrap();
    sim
}

fn names(written: &[std::path::PathBuf]) -> BTreeSet<String> {
    written.iter().map(|p| p.file_name().unwrap().to_string_lossy().into_owned()).collect()
}

const GRID: &str = "paths = 20000\nseed = 3\n[surface]\nalpha = [0.3, 0.8]\n[[material]]\nkind = \"conductor\"\n[[material]]\nkind = \"dielectric\"\neta = 1.5\n[incident]\ntheta_deg = [0, 45]\n[detector]\ncos_theta_bins = 8\nphi_bins = 16\nmax_order = 3\n";

#[test]
fn plot_writes_every_figure_and_a_report_that_shows_them() {
    let dir = tempfile::tempdir().unwrap();
    let sim = run(GRID, dir.path());
    smithwalk::analysis::compare::compare(dir.path(), &[Model::Single, Model::WangCorrelated], Some(20000), Some(2))
        .unwrap();
    let names = names(&plot(dir.path(), &PlotOptions::default()).unwrap());

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
        assert!(image.width() >= 600 && image.height() >= 300, "{name}: {:?}", image.dimensions());
        let colours: BTreeSet<[u8; 3]> = image.pixels().map(|p| p.0).collect();
        assert!(colours.len() > 20, "{name}: only {} colours", colours.len());
    }
    // 4 order rows (1, 2, 3+, all) by 2 incident angles: taller than wide.
    let lobes = image::open(dir.path().join("lobes_g0_R.png")).unwrap();
    assert!(lobes.height() > lobes.width(), "{:?}", (lobes.width(), lobes.height()));

    let html = std::fs::read_to_string(dir.path().join("index.html")).unwrap();
    let linked: BTreeSet<String> = html.split('"').filter(|s| s.ends_with(".png")).map(String::from).collect();
    let pngs: BTreeSet<String> = expected.iter().filter(|n| n.ends_with(".png")).cloned().collect();
    assert_eq!(linked, pngs);
    // A caption under every figure.
    assert_eq!(html.matches("<img ").count(), pngs.len());
    assert_eq!(html.matches("<figcaption>").count(), pngs.len());
    // Columns constant over the run go into the header line, not the case tables.
    assert!(html.contains("ndf ggx") && !html.contains("<th>ndf</th>"), "constant columns in the header");
    // Transmitted lobes state their own convention: theta_o from -z, the refraction side positive.
    assert_eq!(html.matches("measured from −z (positive on the refraction side").count(), 2, "T captions");
    assert_eq!(html.matches("measured from +z (positive on the mirror side").count(), 4, "R captions");
    assert!(html.contains("<th>theta_i_deg</th>") && html.contains("<th>alpha_x</th>"));
    // The fourth row is the run's folded "3+" slot, said so, and the albedo caption is exact for it.
    assert!(html.contains("own folded slot (max_order = 3)") && !html.contains("made by the plot"), "folded row");
    assert!(html.contains("after 3 or more;"), "the albedo caption covers the folded slot");
    // The comparison: per model its lobes and verdict, and the worst lobes.
    assert!(html.contains("Models: single, wang-correlated."), "the header names the models");
    assert!(html.contains("<h2>Measurement against the models</h2>"));
    for heading in ["single: the 5 lobes with the lowest p", "wang-correlated: the 5 lobes with the lowest p"] {
        assert!(html.contains(heading), "{heading}");
    }
}

/// The comparison table reads compare.csv by column name and shows `family_level` and
/// `rejected` where compare.csv has them; without them it computes Sidak's level itself.
#[test]
fn the_report_takes_family_level_and_rejections_from_compare_csv_when_present() {
    let dir = tempfile::tempdir().unwrap();
    run(GRID, dir.path());
    smithwalk::analysis::compare::compare(dir.path(), &[Model::Single], Some(20000), Some(2)).unwrap();
    plot(dir.path(), &PlotOptions::default()).unwrap();
    let html = std::fs::read_to_string(dir.path().join("index.html")).unwrap();
    // 8 cases, order 1, R for all and T for the 4 dielectric ones: 12 lobes; family level 0.01,
    // Sidak per lobe.
    let level = 1.0 - 0.99_f64.powf(1.0 / 12.0);
    let row = format!("<tr><td>single</td><td>12</td><td>0.01</td><td>{level:.2e}</td>");
    assert!(html.contains(&row), "{row} not in the report");

    // The same table with the columns another version of compare writes, in another order.
    let path = dir.path().join("compare.csv");
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines = text.lines();
    let mut out = format!("rejected,family_level,{}\n", lines.next().unwrap());
    for (i, line) in lines.enumerate() {
        out.push_str(&format!("{},0.5,{line}\n", i == 3));
    }
    std::fs::write(&path, out).unwrap();
    crate::common::reseal_comparison(dir.path());
    plot(dir.path(), &PlotOptions::default()).unwrap();
    let html = std::fs::read_to_string(dir.path().join("index.html")).unwrap();
    let row = format!("<tr><td>single</td><td>12</td><td>0.5</td><td>{level:.2e}</td><td>1</td>");
    assert!(html.contains(&row), "{html}");
    assert!(html.contains("rejected in 1 lobes"));
}

#[test]
fn svg_output_goes_to_another_directory_with_vector_text() {
    let dir = tempfile::tempdir().unwrap();
    run(GRID, dir.path());
    let out = dir.path().join("figures");
    let options = PlotOptions { format: Format::Svg, out: Some(out.clone()), ..PlotOptions::default() };
    let names = names(&plot(dir.path(), &options).unwrap());
    assert!(names.iter().all(|n| n.ends_with(".svg") || n == "index.html"), "{names:?}");
    assert!(!dir.path().join("index.html").exists(), "--out leaves the run directory alone");
    let lobes = std::fs::read_to_string(out.join("lobes_g0_R.svg")).unwrap();
    assert!(lobes.starts_with("<svg") && lobes.trim_end().ends_with("</svg>"));
    assert!(
        lobes.contains("f·|cos θ_o| (1/sr)") && lobes.contains("θ_o from +z (deg): + mirror side"),
        "axis labels as text"
    );
    let transmitted = std::fs::read_to_string(out.join("lobes_g1_T.svg")).unwrap();
    assert!(transmitted.contains("θ_o from −z (deg): + refraction side"), "T has its own axis label");
    // Heat maps are vector axes around an embedded raster.
    let heat = std::fs::read_to_string(out.join("heat_case0_R.svg")).unwrap();
    assert!(heat.contains("data:image/png;base64,") && heat.contains("f (1/sr)"));
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(html.contains("src=\"lobes_g0_R.svg\""));
}

#[test]
fn rgb_runs_are_drawn_in_the_channel_asked_for_and_mono_runs_refuse_g_and_b() {
    let dir = tempfile::tempdir().unwrap();
    let toml = "paths = 20000\n[surface]\nalpha = 0.5\n[material]\nkind = \"hammon\"\nalbedo = [0.9, 0.5, 0.1]\n[incident]\ntheta_deg = [0, 60]\n[detector]\ncos_theta_bins = 8\nphi_bins = 16\nmax_order = 2\n";
    run(toml, dir.path());
    let figure = |channel: usize| {
        let out = dir.path().join(format!("c{channel}"));
        plot(dir.path(), &PlotOptions { out: Some(out.clone()), channel, ..PlotOptions::default() }).unwrap();
        (
            std::fs::read(out.join("albedo_vs_theta.png")).unwrap(),
            std::fs::read_to_string(out.join("index.html")).unwrap(),
        )
    };
    let (red, red_html) = figure(0);
    let (blue, blue_html) = figure(2);
    assert_ne!(red, blue, "the channels' albedos differ");
    assert!(red_html.contains("the figures show channel r") && blue_html.contains("the figures show channel b"));

    let mono = tempfile::tempdir().unwrap();
    run(GRID, mono.path());
    let err = plot(mono.path(), &PlotOptions { channel: 1, ..PlotOptions::default() }).unwrap_err().to_string();
    assert!(err.contains("--channel g") && err.contains("one channel"), "{err}");
    assert!(!mono.path().join("index.html").exists(), "no output after an error");
}

#[test]
fn a_wide_sweep_wraps_into_a_grid_of_panels() {
    let dir = tempfile::tempdir().unwrap();
    let toml = "paths = 5000\n[surface]\nalpha = 0.5\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = [0, 9, 18, 27, 36, 45, 54, 63, 72, 81]\n[detector]\ncos_theta_bins = 8\nphi_bins = 16\nmax_order = 1\n";
    run(toml, dir.path());
    plot(dir.path(), &PlotOptions::default()).unwrap();
    // 10 angles x all orders (max_order = 1: the "1+" slot is the all-orders lobe, drawn once):
    // two blocks of 5 columns, 2 rows (h / w = 0.36), instead of one strip of 10 (0.11).
    let lobes = image::open(dir.path().join("lobes_g0_R.png")).unwrap();
    let (w, h) = (lobes.width() as f64, lobes.height() as f64);
    assert!(w < 1800.0 && h / w > 0.3 && h / w < 0.5, "{w} x {h}");
}

/// A dielectric lit from both sides without `max_order`: both groups name their side, and the
/// "orders 4+" row reads as the plot's sum of the run's orders, not as a folded slot.
#[test]
fn both_sides_are_named_and_a_summed_row_is_told_from_a_folded_slot() {
    let dir = tempfile::tempdir().unwrap();
    let toml = "paths = 20000\nseed = 1\n[surface]\nalpha = 1.0\n[material]\nkind = \"dielectric\"\neta = 1.5\n[incident]\ntheta_deg = [0, 60]\nside = [\"outside\", \"inside\"]\n[detector]\ncos_theta_bins = 8\nphi_bins = 16\n";
    run(toml, dir.path());
    plot(dir.path(), &PlotOptions::default()).unwrap();
    let html = std::fs::read_to_string(dir.path().join("index.html")).unwrap();
    for side in ["outside", "inside"] {
        assert!(
            html.contains(&format!("<h2>GGX, α = 1, dielectric eta=1.5, light from {side}, φ_i = 0.0°</h2>")),
            "{side}"
        );
    }
    assert!(!html.contains("side inside"), "the side reads the same for both groups");
    assert!(html.contains("made by the plot, of its orders 4 and higher, without error bars"), "summed row");
    assert!(!html.contains("folded slot"), "no folded slot in a run without max_order");
    assert!(html.contains("after 4 or more;") && html.contains("side the light comes from"), "albedo caption");
}

/// Issue 36 item 10 and 14: cases of a sweep over the incident azimuth are told apart wherever
/// the polar angle is shown (report sections, heat-map captions, lobe panels); Beckmann is
/// spelled as the literature spells it; a roughness sweep over two decades is drawn on a
/// logarithmic axis.
#[test]
fn the_azimuth_and_the_ndf_are_named_and_decades_of_roughness_get_a_log_axis() {
    let dir = tempfile::tempdir().unwrap();
    let toml = "paths = 2000\nseed = 1\n[surface]\nndf = \"beckmann\"\nalpha = [0.01, 0.1, 1.0]\n[material]\nkind = \"conductor\"\nfresnel = \"none\"\n[incident]\ntheta_deg = [0, 60]\nphi_deg = [0, 45]\n[detector]\ncos_theta_bins = 8\nphi_bins = 16\nmax_order = 2\n";
    run(toml, dir.path());
    let out = dir.path().join("figures");
    plot(dir.path(), &PlotOptions { format: Format::Svg, out: Some(out.clone()), ..PlotOptions::default() }).unwrap();
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    for phi in ["0.0", "45.0"] {
        assert!(html.contains(&format!("Beckmann, α = 0.1, conductor F=1, φ_i = {phi}°</h2>")), "section of φ_i {phi}");
        assert!(html.contains(&format!("θ_i = 60.0°, φ_i = {phi}°), reflection")), "heat-map caption of φ_i {phi}");
    }
    assert!(!html.contains("BECKMANN"));
    let albedo = std::fs::read_to_string(out.join("albedo_vs_alpha.svg")).unwrap();
    assert!(albedo.contains("(log scale)"), "roughness from 0.01 to 1 on a linear axis");
}

/// Issue 38 point 7: a run with Student-T cases gets `albedo_vs_gamma`, the per-order albedos
/// against `1/gamma` with its GGX (0.5) and Beckmann (0) cases on the same axis, one panel per
/// roughness; the report shows it with its caption. (A run without Student-T has no such figure:
/// `plot_writes_every_figure_and_a_report_that_shows_them` lists every file.)
#[test]
fn a_student_t_sweep_gets_an_albedo_figure_against_the_shape() {
    let dir = tempfile::tempdir().unwrap();
    let toml = "paths = 2000\nseed = 1\n[surface]\nndf = [\"student-t\", \"ggx\", \"beckmann\"]\ngamma = [1.6, 4]\nalpha = [0.3, 1.0]\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = 30\n[detector]\ncos_theta_bins = 4\nphi_bins = 8\nmax_order = 2\n";
    run(toml, dir.path());
    let out = dir.path().join("figures");
    plot(dir.path(), &PlotOptions { format: Format::Svg, out: Some(out.clone()), ..PlotOptions::default() }).unwrap();
    let figure = std::fs::read_to_string(out.join("albedo_vs_gamma.svg")).unwrap();
    assert!(figure.contains("1/γ (Student-T shape; Beckmann 0, GGX 0.5)"));
    for panel in ["α = 0.3", "α = 1"] {
        assert!(figure.contains(panel), "panel {panel}");
    }
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(html.contains("albedo_vs_gamma.svg") && html.contains("the Student-T shape as 1/γ"));
}
