//! The format of a run directory, in one place (docs/run-directory.md): every file smithwalk
//! writes into it and, for each table, its columns in order with their units and meaning.
//! Writers take their headers from here ([`TableSchema::header`]), readers find their columns
//! through here (`io::rundir`'s `Table::column`), and the Python package asks the
//! extension for them (`smithwalk.columns()`), so that a column is named once.

/// The version of the run directory's format, written to `run.json` as `format_version`.
/// Raise it when a file or column changes meaning or disappears (adding a column does not):
/// readers refuse a run directory of a newer format than theirs.
pub const FORMAT_VERSION: u32 = 1;

/// One column of a table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Column {
    /// The header cell.
    pub name: &'static str,
    /// The unit of its values (empty for labels, indices and dimensionless ratios).
    pub unit: &'static str,
    /// What it holds.
    pub meaning: &'static str,
}

const fn column(name: &'static str, unit: &'static str, meaning: &'static str) -> Column {
    Column { name, unit, meaning }
}

// The columns that identify a case, in the order every table that names cases writes them.
pub const CASE: Column = column("case", "", "case index, in the order the config's sweep expands");
pub const NDF: Column = column("ndf", "", "normal distribution: ggx, beckmann or student-t");
pub const ALPHA_X: Column = column("alpha_x", "", "roughness along x (slope standard deviation / sqrt 2)");
pub const ALPHA_Y: Column = column("alpha_y", "", "roughness along y");
pub const GAMMA: Column = column("gamma", "", "Student-T shape gamma (empty for ggx and beckmann)");
pub const HEIGHT: Column = column("height", "", "height distribution of the microsurface: uniform or gaussian");
pub const SMITH: Column = column("smith", "", "masking function: exact, or an approximation");
pub const NORMALS: Column = column("normals", "", "facet normal sampling: visible, or an alternative");
pub const MATERIAL: Column = column("material", "", "the facets' material, as the config spells it");
pub const THETA_I_DEG: Column =
    column("theta_i_deg", "degree", "incident polar angle, of the direction towards the light");
pub const PHI_I_DEG: Column = column(
    "phi_i_deg",
    "degree",
    "incident azimuth; phi_o is measured from it, so the mirror direction is at phi_o = 180",
);
pub const SIDE: Column = column("side", "", "the side the light comes from: outside or inside");

/// The leading columns of `lobes.csv`, `summary.csv` and `compare.csv`.
pub const CASE_COLUMNS: [Column; 12] =
    [CASE, NDF, ALPHA_X, ALPHA_Y, GAMMA, HEIGHT, SMITH, NORMALS, MATERIAL, THETA_I_DEG, PHI_I_DEG, SIDE];

// A lobe and a bin.
pub const ORDER: Column = column("order", "", "order slot: 0 all orders, k >= 1 order k (the folded slot K is K+)");
pub const HEMISPHERE: Column = column("hemisphere", "", "R reflection, T transmission");
pub const SUMMARY_ROW: Column =
    column("hemisphere", "", "R reflection, T transmission, absorbed, or lost (trapped, invalid, runaway)");
/// Present in RGB runs only.
pub const CHANNEL: Column = column("channel", "", "colour channel r, g or b (RGB runs only)");
pub const COS_LO: Column = column("cos_lo", "", "lower edge of the bin in cos theta_o (negative below the surface)");
pub const COS_HI: Column = column("cos_hi", "", "upper edge of the bin in cos theta_o");
pub const PHI_LO_DEG: Column =
    column("phi_lo_deg", "degree", "lower edge of the bin in phi_o (from the incident azimuth)");
pub const PHI_HI_DEG: Column = column("phi_hi_deg", "degree", "upper edge of the bin in phi_o");
pub const ENERGY: Column =
    column("energy", "", "fraction of the incident energy leaving through the bin (the integral of f cos over it)");
pub const ENERGY_STDERR: Column = column("energy_stderr", "", "standard error of energy");
pub const COUNT: Column = column("count", "", "photons that put energy into the bin");
pub const BSDF: Column = column(
    "bsdf",
    "1/sr",
    "energy over the bin's projected solid angle (the integral of abs(cos theta_o)): the bin's average BSDF",
);
pub const BSDF_STDERR: Column = column("bsdf_stderr", "1/sr", "standard error of bsdf");
pub const THETA_O_DEG: Column = column(
    "theta_o_deg",
    "degree",
    "the bin's centre: theta_o at the mid-point of its cos limits (above 90 below the surface)",
);
pub const PHI_O_DEG: Column = column("phi_o_deg", "degree", "the bin's centre: the mid-point of its phi limits");
pub const SOLID_ANGLE: Column =
    column("solid_angle", "sr", "the bin's solid angle: (cos_hi - cos_lo) times its phi width in radians");

// summary.csv.
pub const PATHS: Column = column("paths", "", "photons traced for the case");
pub const ALBEDO: Column = column("albedo", "", "energy per photon of the row (1 - escaped energy for absorbed)");
pub const ALBEDO_STDERR: Column = column("albedo_stderr", "", "standard error of albedo");
pub const ALBEDO_VOV: Column =
    column("albedo_vov", "", "variance of the variance of albedo (empty for lost unless it is 0)");
pub const FOLDED: Column = column("folded", "", "true in the folded slot K+ (detector.max_order = K)");

// models.csv: after the key columns, two columns per model compared, named after the model.
/// A model's energy per bin; the header cell is the model's name (for example `single`).
pub const MODEL_ENERGY: Column =
    column("<model>", "", "the model's energy per photon in the bin (empty: no such lobe)");
/// Its standard error; the header cell is the model's name followed by [`STDERR_SUFFIX`].
pub const MODEL_STDERR: Column =
    column("<model>_stderr", "", "standard error of the model's energy (0 for closed forms)");
/// What follows a model's name in the header of its standard-error column.
pub const STDERR_SUFFIX: &str = "_stderr";

// compare.csv.
pub const MODEL: Column = column("model", "", "the model compared");
pub const CHI2: Column = column("chi2", "", "chi-square statistic of the lobe (docs/compare.md)");
pub const DOF: Column = column("dof", "", "its degrees of freedom, after pooling");
pub const P_VALUE: Column = column("p_value", "", "its p-value");
pub const REL_L1: Column = column("rel_l1", "", "L1 norm of measured minus model, over the model's");
pub const REL_L2: Column = column("rel_l2", "", "L2 norm of measured minus model, over the model's");
pub const ALBEDO_MEASURED: Column = column("albedo_measured", "", "the lobe's measured albedo");
pub const ALBEDO_MEASURED_STDERR: Column = column("albedo_measured_stderr", "", "its standard error");
pub const ALBEDO_MODEL: Column = column("albedo_model", "", "the model's albedo of the lobe");
pub const ALBEDO_MODEL_STDERR: Column = column("albedo_model_stderr", "", "its standard error");
pub const ALBEDO_DIFF_SE: Column =
    column("albedo_diff_se", "", "measured minus model albedo in units of their combined standard error");
pub const FAMILY_LEVEL: Column = column("family_level", "", "the significance level of the model's family of tests");
pub const LOBE_LEVEL: Column = column("lobe_level", "", "the per-lobe level (Sidak correction of family_level)");
pub const REJECTED: Column = column("rejected", "", "true when p_value < lobe_level");

/// A CSV table of the run directory: its file name and columns in order. The channel column
/// is written by RGB runs only; `models.csv` repeats [`MODEL_ENERGY`] and [`MODEL_STDERR`]
/// for each model compared.
#[derive(Clone, Copy, Debug)]
pub struct TableSchema {
    /// The file name in the run directory.
    pub file: &'static str,
    /// What one row is.
    pub row: &'static str,
    /// Every column, in order.
    pub columns: &'static [Column],
}

const LOBES_COLUMNS: [Column; 27] = concat(
    &CASE_COLUMNS,
    &[
        ORDER,
        HEMISPHERE,
        CHANNEL,
        COS_LO,
        COS_HI,
        PHI_LO_DEG,
        PHI_HI_DEG,
        ENERGY,
        ENERGY_STDERR,
        COUNT,
        BSDF,
        BSDF_STDERR,
        THETA_O_DEG,
        PHI_O_DEG,
        SOLID_ANGLE,
    ],
);

const SUMMARY_COLUMNS: [Column; 20] =
    concat(&CASE_COLUMNS, &[PATHS, ORDER, SUMMARY_ROW, CHANNEL, ALBEDO, ALBEDO_STDERR, ALBEDO_VOV, FOLDED]);

const COMPARE_COLUMNS: [Column; 30] = concat(
    &CASE_COLUMNS,
    &[
        MODEL,
        ORDER,
        HEMISPHERE,
        CHANNEL,
        CHI2,
        DOF,
        P_VALUE,
        REL_L1,
        REL_L2,
        ALBEDO_MEASURED,
        ALBEDO_MEASURED_STDERR,
        ALBEDO_MODEL,
        ALBEDO_MODEL_STDERR,
        ALBEDO_DIFF_SE,
        FOLDED,
        FAMILY_LEVEL,
        LOBE_LEVEL,
        REJECTED,
    ],
);

/// `head` followed by `tail`, as an array of `N = head.len() + tail.len()` columns (checked
/// when the constants above are built, at compile time).
const fn concat<const N: usize>(head: &[Column], tail: &[Column]) -> [Column; N] {
    assert!(head.len() + tail.len() == N);
    let mut out = [CASE; N];
    let mut i = 0;
    while i < N {
        out[i] = if i < head.len() { head[i] } else { tail[i - head.len()] };
        i += 1;
    }
    out
}

/// `lobes.csv`: the measured lobes.
pub const LOBES: TableSchema = TableSchema {
    file: "lobes.csv",
    row: "one bin of one lobe: per case, order slot, hemisphere, bin (cos index, then phi index) and channel",
    columns: &LOBES_COLUMNS,
};

/// `summary.csv`: albedos, absorbed and lost energy.
pub const SUMMARY: TableSchema = TableSchema {
    file: "summary.csv",
    row: "per case, order slot and hemisphere an albedo, then the absorbed and the lost energy, per channel",
    columns: &SUMMARY_COLUMNS,
};

/// `models.csv`: the models' lobes, row for row aligned with `lobes.csv`; the per-model columns
/// come last.
pub const MODELS: TableSchema = TableSchema {
    file: "models.csv",
    row: "the bin of the same line of lobes.csv; per model compared its energy and standard error",
    columns: &[
        CASE,
        ORDER,
        HEMISPHERE,
        CHANNEL,
        COS_LO,
        COS_HI,
        PHI_LO_DEG,
        PHI_HI_DEG,
        FOLDED,
        MODEL_ENERGY,
        MODEL_STDERR,
    ],
};

/// `compare.csv`: one statistical test per lobe and model.
pub const COMPARE: TableSchema = TableSchema {
    file: "compare.csv",
    row: "one tested lobe (case, order slot, hemisphere, channel) and model",
    columns: &COMPARE_COLUMNS,
};

/// Every table of a run directory, in the order docs/run-directory.md lists them.
pub const TABLES: [TableSchema; 4] = [LOBES, SUMMARY, MODELS, COMPARE];

/// The run's record: the resolved config, the cases with their energy balance, run metadata
/// (`format_version` among them) and the digests of the run's tables.
pub const RUN_JSON: &str = "run.json";

/// The files a finished run writes, as one atomic set; `run.json` records the tables' digests.
pub const RUN_FILES: [&str; 3] = [LOBES.file, SUMMARY.file, RUN_JSON];

/// A JSON record of the run directory: its file name and its top-level fields.
#[derive(Clone, Copy, Debug)]
pub struct RecordSchema {
    /// The file name in the run directory.
    pub file: &'static str,
    /// Every top-level field, in the order written (units are empty).
    pub fields: &'static [Column],
}

/// `compare.json`: the seal of `compare`'s tables. It records their digests, the run they
/// belong to and the comparison's settings; `compare` writes it last, and readers refuse
/// tables it does not describe (`io::compare_json`).
pub const COMPARE_JSON: RecordSchema = RecordSchema {
    file: "compare.json",
    fields: &[
        column("format_version", "", "the run directory's format, as in run.json"),
        column("smithwalk_version", "", "the version of smithwalk that compared"),
        column("run_id", "", "the run_id of the run.json compared"),
        column(
            "run_tables",
            "",
            "SHA-256 of the run's lobes.csv and summary.csv: the comparison belongs to a run with these tables only",
        ),
        column(
            "settings",
            "",
            "models (in the order compared), paths per case of the Monte Carlo models, seed, family_level, \
             external and albedo_table (the paths given, or null)",
        ),
        column("files", "", "models.csv and compare.csv: their bytes and SHA-256"),
        column("self_sha256", "", "SHA-256 of this file's text with these 64 digits written as zeros"),
    ],
};

/// The files `compare` derives from a run, as one atomic set, `compare.json` last; a new run
/// into the directory removes them.
pub const COMPARE_FILES: [&str; 3] = [MODELS.file, COMPARE.file, COMPARE_JSON.file];

impl TableSchema {
    /// The header of this table: its columns, without the channel column unless `rgb`, and in
    /// `models.csv` each model's pair of columns, named after `models`, in their order.
    pub fn header(&self, rgb: bool, models: &[&str]) -> Vec<String> {
        let per_model = |c: &Column| *c == MODEL_ENERGY || *c == MODEL_STDERR;
        let mut header: Vec<String> = self
            .columns
            .iter()
            .filter(|c| (rgb || **c != CHANNEL) && !per_model(c))
            .map(|c| c.name.to_string())
            .collect();
        if self.columns.iter().any(per_model) {
            header.extend(models.iter().flat_map(|m| [m.to_string(), format!("{m}{STDERR_SUFFIX}")]));
        }
        header
    }
}
