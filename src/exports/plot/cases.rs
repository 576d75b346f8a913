//! How a run's cases are grouped into figures and named in titles and captions.

use std::collections::BTreeMap;

use crate::io::output::case_fields;
use crate::io::rundir::RunDir;
use crate::io::schema::CASE_COLUMNS;
use crate::setup::cases::Case;

/// The case fields without the case index and the columns `swept`, which identify a group of
/// cases that differ only in those columns.
fn group_key(case: &Case, swept: &[usize]) -> Vec<String> {
    case_fields(case).into_iter().enumerate().filter(|(i, _)| *i != 0 && !swept.contains(i)).map(|(_, f)| f).collect()
}

/// The index in `CASE_COLUMNS` of the case column called `name`: figures name the columns
/// they sweep, so that a column added to the schema does not shift them.
pub(super) fn case_column(name: &str) -> usize {
    CASE_COLUMNS.iter().position(|c| c.name == name).expect("a case column of the schema")
}

/// Cases that differ only in the columns `swept` (indices into `CASE_COLUMNS`), in order of
/// their first case, each sorted by the incident angle.
pub(super) fn groups<'a>(cases: impl IntoIterator<Item = &'a Case>, swept: &[usize]) -> Vec<Vec<&'a Case>> {
    let mut map: BTreeMap<Vec<String>, Vec<&Case>> = BTreeMap::new();
    for case in cases {
        map.entry(group_key(case, swept)).or_default().push(case);
    }
    let mut out: Vec<Vec<&Case>> = map.into_values().collect();
    out.sort_by_key(|cases| cases[0].index);
    for cases in &mut out {
        cases.sort_by(|a, b| a.theta_i_deg.total_cmp(&b.theta_i_deg).then(a.roughness().x.total_cmp(&b.roughness().x)));
    }
    out
}

/// The indices of the case columns (after `case`) whose value differs between cases.
pub(super) fn varying(cases: &[Case]) -> Vec<usize> {
    let fields: Vec<Vec<String>> = cases.iter().map(case_fields).collect();
    (1..CASE_COLUMNS.len()).filter(|&c| fields.iter().any(|f| f[c] != fields[0][c])).collect()
}

/// An angle in degrees as captions name it (`θ_i = 30.0°`).
fn angle(symbol: &str, degrees: f64) -> String {
    format!("{symbol} = {degrees:.1}°")
}

/// The incident direction as titles name it, polar angle and azimuth (`θ_i = 30.0°, φ_i =
/// 0.0°`): two cases of a sweep over `φ_i` must not look alike.
pub(super) fn incidence(case: &Case) -> String {
    format!("{}, {}", angle("θ_i", case.theta_i_deg), angle("φ_i", case.phi_i_deg))
}

/// The incident azimuth as titles name it (`φ_i = 45.0°`), for figures that sweep `θ_i`.
pub(super) fn azimuth(case: &Case) -> String {
    angle("φ_i", case.phi_i_deg)
}

/// An NDF's name as the literature spells it (`GGX`, `Beckmann`), from its config name.
fn ndf_label(name: &str) -> String {
    match name {
        "ggx" => "GGX".to_string(),
        "beckmann" => "Beckmann".to_string(),
        other => other.to_string(),
    }
}

/// How a case column reads in captions: a name and the value (`α_x = 0.5`, `θ_i = 30°`).
fn pretty_field(column: usize, value: &str) -> String {
    let degrees = || value.parse::<f64>().unwrap_or(f64::NAN);
    match CASE_COLUMNS[column].name {
        "alpha_x" => format!("α_x = {value}"),
        "alpha_y" => format!("α_y = {value}"),
        "theta_i_deg" => angle("θ_i", degrees()),
        "phi_i_deg" => angle("φ_i", degrees()),
        "material" => value.to_string(),
        "side" => format!("light from {value}"),
        name => format!("{name} {value}"),
    }
}

/// The fields of `case` that vary over the run, except those of `skip`, for captions.
pub(super) fn pretty_fields(run: &RunDir, case: &Case, skip: &[usize]) -> String {
    let columns: Vec<usize> = varying(&run.cases).into_iter().filter(|c| !skip.contains(c)).collect();
    describe(&case_fields(case), &columns).join(", ")
}

/// How the case columns `columns` of a case (its `fields`) read in captions, an isotropic
/// roughness as one value.
pub(super) fn describe(fields: &[String], columns: &[usize]) -> Vec<String> {
    let (x, y) = (case_column("alpha_x"), case_column("alpha_y"));
    let isotropic = columns.contains(&x) && columns.contains(&y) && fields[x] == fields[y];
    columns
        .iter()
        .filter(|&&c| !(isotropic && c == y))
        .map(|&c| if isotropic && c == x { format!("α = {}", fields[x]) } else { pretty_field(c, &fields[c]) })
        .collect()
}

/// A self-contained name of a case's surface and material (NDF, roughness, material, and the
/// Smith and normals settings when they are not the defaults) and the side the light comes
/// from, named when it is not outside or when the run has both sides.
pub(super) fn surface_label(run: &RunDir, case: &Case) -> String {
    let alpha = if case.roughness().x == case.roughness().y {
        format!("α = {}", case.roughness().x)
    } else {
        format!("α = ({}, {})", case.roughness().x, case.roughness().y)
    };
    let fields = case_fields(case);
    let field = |name: &str| &fields[case_column(name)];
    let mut label = format!("{}, {alpha}", ndf_label(field("ndf")));
    if !field("gamma").is_empty() {
        label.push_str(&format!(", γ = {}", field("gamma")));
    }
    label.push_str(&format!(", {}", field("material")));
    for (name, default) in [("smith", "exact"), ("normals", "vndf")] {
        if field(name) != default {
            label.push_str(&format!(", {name} {}", field(name)));
        }
    }
    let side = case_column("side");
    if fields[side] != "outside" || varying(&run.cases).contains(&side) {
        label.push_str(&format!(", {}", pretty_field(side, &fields[side])));
    }
    label
}

/// The name of a group of cases that differ only in `θ_i` (a lobe figure, a section of the
/// report): the surface and the incident azimuth they share.
pub(super) fn group_label(run: &RunDir, case: &Case) -> String {
    format!("{}, {}", surface_label(run, case), azimuth(case))
}
