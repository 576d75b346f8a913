//! The per-order rows of the figures: which order slots a run's figures show, the bins of a
//! row (summed over slots for "orders K+"), and how rows read in labels and captions.

use std::borrow::Cow;

use crate::io::rundir::{BinValue, Lobes, RunDir};

/// The most bounce-order rows a figure shows besides "all orders": orders 1 to 3 and a fourth
/// row that holds the rest.
const ORDER_ROWS: usize = 4;

/// A row of the per-order figures (lobes, heat maps, albedos).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Row {
    /// One order slot of the run as written: order k, the run's folded "K+" slot
    /// (`max_order = K`), or 0 (all orders).
    Slot(usize),
    /// Orders k and higher, summed by the figure over the run's slots from k up (the run has
    /// more orders than the figure has rows).
    From(usize),
}

/// The rows of a run whose highest order slot is `highest`, in plotting order: 1, 2, ... up to
/// [`ORDER_ROWS`], the last of them "K+" (the sum of every order from K up) when the run has
/// more, then all orders. A run with one order slot gets the all-orders row only: its slot 1
/// holds the same lobe as slot 0 (the "1+" slot of `max_order = 1`, which `smithwalk compare`
/// also tests once, as slot 0; or order 1 where no light bounced twice).
pub(super) fn rows(highest: usize) -> Vec<Row> {
    let mut out: Vec<Row> = if highest > ORDER_ROWS {
        (1..ORDER_ROWS).map(Row::Slot).chain([Row::From(ORDER_ROWS)]).collect()
    } else if highest > 1 {
        (1..=highest).map(Row::Slot).collect()
    } else {
        Vec::new()
    };
    out.push(Row::Slot(0));
    out
}

/// Whether `rows` is the all-orders row alone (a run with one order slot, see [`rows`]).
pub(super) fn all_orders_only(rows: &[Row]) -> bool {
    rows == [Row::Slot(0)]
}

/// The highest order slot of the lobes of one case, hemisphere and channel (0 if none).
pub(super) fn highest_slot(lobes: &Lobes, case: usize, hemisphere: &str, channel: usize) -> usize {
    lobes.lobes.keys().filter(|k| k.0 == case && k.2 == hemisphere && k.3 == channel).map(|k| k.1).max().unwrap_or(0)
}

/// The bins of `row` for one case, hemisphere and channel of `lobes` (the measurement or a
/// model), or `None` where `lobes` lacks the lobe. A row `From(k)` sums the slots k to `highest`
/// (the measurement's highest slot of the case), all of which `lobes` must have: energies and
/// BSDF values exactly; its standard errors are NaN (no error bar) when it sums more than one
/// slot, since one photon's energy in one bin can come from several orders (Fresnel splitting)
/// and lobes.csv has no covariances between orders.
pub(super) fn row_bins<'a>(
    lobes: &'a Lobes,
    row: Row,
    (case, hemisphere, channel): (usize, &str, usize),
    highest: usize,
) -> Option<Cow<'a, [BinValue]>> {
    match row {
        Row::Slot(slot) => lobes.get(case, slot, hemisphere, channel).map(Cow::Borrowed),
        Row::From(k) if highest == k => lobes.get(case, k, hemisphere, channel).map(Cow::Borrowed),
        Row::From(k) => {
            let slots = (k..=highest).map(|s| lobes.get(case, s, hemisphere, channel)).collect::<Option<Vec<_>>>()?;
            let mut sum = vec![
                BinValue { energy_stderr: f64::NAN, bsdf_stderr: f64::NAN, ..BinValue::default() };
                slots.first()?.len()
            ];
            for bins in slots {
                for (total, b) in sum.iter_mut().zip(bins) {
                    total.energy += b.energy;
                    total.bsdf += b.bsdf;
                }
            }
            Some(Cow::Owned(sum))
        }
    }
}

/// The K of the row "orders K+" among `rows`, if there is one, and whether it is the run's
/// folded slot (`max_order = K`) rather than a sum the figure makes.
pub(super) fn open_row(run: &RunDir, rows: &[Row]) -> Option<(usize, bool)> {
    let folded = run.config.detector.max_order.map(|k| k as usize).filter(|&k| k > 0 && rows.contains(&Row::Slot(k)));
    folded
        .map(|k| (k, true))
        .or_else(|| rows.iter().find_map(|r| if let Row::From(k) = r { Some((*k, false)) } else { None }))
}

/// What a caption says about the row "orders K+", if the figure has one (empty otherwise):
/// whether it is the run's folded slot (`max_order = K`, tallied by the walk, with error bars)
/// or a sum the figure makes of the run's orders K and higher, and with `bars`, why that sum has
/// none; with `max_order = 1`, that the run's "1+" slot is drawn once, as all orders.
pub(super) fn folded_note(run: &RunDir, rows: &[Row], bars: bool) -> String {
    if all_orders_only(rows) && run.config.detector.max_order == Some(1) {
        return " The run tallies every order in one slot (max_order = 1), \"orders 1+\", which is the all-orders \
                lobe: it is drawn once, as \"all orders\"."
            .to_string();
    }
    let Some((k, folded)) = open_row(run, rows) else {
        return String::new();
    };
    if folded {
        let with = if bars { ", with its standard errors" } else { "" };
        return format!(
            " \"orders {k}+\" is the run's own folded slot (max_order = {k}): the energy the walk tallied after {k} \
             or more bounces{with}."
        );
    }
    let why = if bars {
        ", without error bars: lobes.csv and summary.csv have no covariances between orders (docs/figures.md)"
    } else {
        ""
    };
    format!(
        " \"orders {k}+\" is not a slot of the run but the sum, made by the plot, of its orders {k} and higher{why}."
    )
}

/// How an order slot reads in figures and tables: "order k", "orders K+" for the run's folded
/// slot, "all orders" for slot 0.
pub(super) fn slot_label(run: &RunDir, slot: usize) -> String {
    match slot {
        0 => "all orders".into(),
        k if run.config.detector.max_order == Some(k as u32) => format!("orders {k}+"),
        k => format!("order {k}"),
    }
}

/// How a row reads in figures: as its slot, or "orders K+" for a row the figure sums.
pub(super) fn row_label(run: &RunDir, row: Row) -> String {
    match row {
        Row::Slot(slot) => slot_label(run, slot),
        Row::From(k) => format!("orders {k}+"),
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// The run directory of the config `toml`, walked on 1 thread and written to a temporary
    /// directory (kept alive by the first element).
    pub(crate) fn written_run(toml: &str) -> (tempfile::TempDir, RunDir) {
        let dir = tempfile::tempdir().unwrap();
        let config = crate::setup::config::Config::parse(toml).unwrap();
        let sim = crate::engine::simulate(&config, Some(1), false).unwrap();
        crate::io::output::write_outputs(&sim, &config, dir.path()).unwrap();
        let run = RunDir::open(dir.path()).unwrap();
        (dir, run)
    }

    #[test]
    fn runs_with_more_than_four_orders_get_a_fourth_row_of_every_order_above_three() {
        assert_eq!(rows(13), [Row::Slot(1), Row::Slot(2), Row::Slot(3), Row::From(4), Row::Slot(0)]);
        assert_eq!(rows(5), rows(13));
        assert_eq!(rows(4), [Row::Slot(1), Row::Slot(2), Row::Slot(3), Row::Slot(4), Row::Slot(0)]);
        assert_eq!(rows(2), [Row::Slot(1), Row::Slot(2), Row::Slot(0)]);
    }

    /// The summed "4+" row of a run without `max_order` holds, bin by bin, the all-orders lobe
    /// minus orders 1 to 3, in both hemispheres; its standard errors are NaN (not drawn).
    #[test]
    fn the_summed_row_is_all_orders_minus_the_orders_above_it() {
        let (_dir, run) = written_run(
            "paths = 20000\nseed = 5\n[surface]\nalpha = 0.8\n[material]\nkind = \"dielectric\"\neta = 1.5\n[incident]\ntheta_deg = 60\nside = \"inside\"\n[detector]\ncos_theta_bins = 4\nphi_bins = 8\n",
        );
        let measured = run.measured().unwrap();
        for hemisphere in ["R", "T"] {
            let highest = highest_slot(&measured, 0, hemisphere, 0);
            assert!(highest > 5, "{hemisphere}: orders up to {highest} only");
            assert_eq!(rows(highest)[3], Row::From(4));
            let folded = row_bins(&measured, Row::From(4), (0, hemisphere, 0), highest).unwrap();
            let slot = |s| measured.get(0, s, hemisphere, 0).unwrap();
            for (i, b) in folded.iter().enumerate() {
                let rest = slot(0)[i].energy - slot(1)[i].energy - slot(2)[i].energy - slot(3)[i].energy;
                assert!((b.energy - rest).abs() <= 1e-12, "{hemisphere} bin {i}: {} against {rest}", b.energy);
                assert!(b.energy_stderr.is_nan() && b.bsdf_stderr.is_nan());
            }
            assert!(folded.iter().map(|b| b.energy).sum::<f64>() > 0.0);
        }
    }
}
