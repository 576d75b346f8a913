//! A lobe's key (case, order slot, hemisphere, channel) as compare names it, which slot the
//! run folds, and which lobes are tested, so that like is compared with like and no lobe twice.

use crate::engine::detector::Hemisphere;
use crate::setup::cases::Case;
use crate::setup::config::{Config, Model};

/// A hemisphere's name as `lobes.csv` writes it (`R`, `T`).
pub(super) fn hemisphere_name(h: Hemisphere) -> String {
    format!("{h:?}")
}

/// A channel's name in an RGB run (`r`, `g`, `b`), empty in a mono run.
pub(super) fn channel_name(rgb: bool, channel: usize) -> &'static str {
    if rgb { ["r", "g", "b"][channel] } else { "" }
}

/// The run's folded slot `K` ("K+") when `max_order = K`.
pub(super) fn folded_slot(config: &Config) -> Option<usize> {
    config.detector.max_order.map(|k| k as usize)
}

/// Whether `model`'s lobe (of `case`, order slot `order`, channel `channel`) is tested, so that
/// no lobe is tested twice: with `max_order = 1` the "1+" slot is the all-orders lobe (slot 0)
/// again; in an RGB run, a material with one value per parameter has the same walk weights in
/// every channel, and so has every built-in model of it, so its three channels are one lobe,
/// tested once as channel `r` (a material given per channel is tested per channel). A user's
/// `--external` model may differ between channels whatever the material: all are tested.
pub(super) fn is_tested(config: &Config, case: &Case, model: Model, order: usize, channel: usize) -> bool {
    let channel_of_its_own = channel == 0 || case.material_spec.is_rgb() || model == Model::External;
    !(folded_slot(config) == Some(1) && order == 1) && channel_of_its_own
}

/// A channel's index from its name (`None` and `r`: 0).
pub(super) fn channel_index(channel: Option<&str>) -> usize {
    match channel {
        Some("g") => 1,
        Some("b") => 2,
        _ => 0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn single_scattering_is_never_tested_against_a_slot_that_holds_other_orders() {
        let mut config: Config = toml::from_str(
            "paths = 1000\n[surface]\nalpha = 0.5\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = 0\n\
             [detector]\ncos_theta_bins = 2\nphi_bins = 2\nmax_order = 1\n",
        )
        .unwrap();
        let case = &crate::setup::cases::expand(&config).unwrap()[0];
        // max_order = 1: slot 1 is "1+" = slot 0, tested once, and `single` is skipped.
        let single = Model::Single;
        assert!(is_tested(&config, case, single, 0, 0) && !is_tested(&config, case, single, 1, 0));
        config.detector.max_order = Some(2);
        assert!(is_tested(&config, case, single, 1, 0) && is_tested(&config, case, single, 2, 0));
    }

    #[test]
    fn the_equal_channels_of_a_one_valued_material_are_tested_once() {
        let config: Config = toml::from_str(
            "paths = 1000\n[surface]\nalpha = 0.5\n[[material]]\nkind = \"conductor\"\n\
             [[material]]\nkind = \"conductor\"\nfresnel = \"schlick\"\nf0 = [0.2, 0.6, 1.0]\n\
             [incident]\ntheta_deg = 0\n[detector]\ncos_theta_bins = 2\nphi_bins = 2\n",
        )
        .unwrap();
        let cases = crate::setup::cases::expand(&config).unwrap();
        let tested = |case: &Case, model| (0..3).filter(|&c| is_tested(&config, case, model, 1, c)).count();
        assert_eq!((tested(&cases[0], Model::Single), tested(&cases[1], Model::Single)), (1, 3));
        assert_eq!((tested(&cases[0], Model::HeitzNee), tested(&cases[1], Model::KullaConty)), (1, 3));
        // A user's model may differ between channels where the walk does not.
        assert_eq!((tested(&cases[0], Model::External), tested(&cases[1], Model::External)), (3, 3));
    }
}
