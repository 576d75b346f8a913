//! Reading and checking a table of D(theta_m) (docs/theory.md §1.7): the CSV form and one
//! error per fault, naming the line and the value.

use std::fmt;

/// The CSV header a table starts with (after comment lines): the normal's polar angle in
/// degrees and D in any unit proportional to sr^-1.
pub const HEADER: &str = "theta_m_deg,D";
/// Fewest rows a table may have.
pub const MIN_ROWS: usize = 16;
/// Largest step between consecutive angles (degrees): a coarser table cannot resolve a lobe of
/// roughness 0.1 (a width of about 6 degrees) with its linear interpolation.
pub const MAX_STEP_DEG: f64 = 1.0;

/// Why a table of D(theta_m) was refused. `line` counts the CSV file's lines from 1 (the header
/// included); [`super::Tabulated::new`] numbers its rows as that file would, the first at 2.
#[derive(Clone, Debug, PartialEq)]
pub enum TableError {
    /// The first line that is not a comment is not [`HEADER`].
    Header {
        /// What the line holds.
        found: String,
    },
    /// A line does not hold two comma-separated numbers.
    Row {
        /// The line.
        line: usize,
        /// Its text.
        text: String,
    },
    /// Fewer rows than [`MIN_ROWS`].
    TooFewRows {
        /// How many there are.
        rows: usize,
    },
    /// An angle or a value of D is NaN or infinite.
    NotFinite {
        /// The line.
        line: usize,
        /// `theta_m_deg` or `D`.
        column: &'static str,
        /// The value.
        value: f64,
    },
    /// A negative value of D.
    Negative {
        /// The line.
        line: usize,
        /// The value.
        value: f64,
    },
    /// The first angle is not 0.
    FirstAngle {
        /// The angle (degrees).
        theta: f64,
    },
    /// An angle not above the one before it.
    NotIncreasing {
        /// The line.
        line: usize,
        /// The angle (degrees).
        theta: f64,
        /// The angle before it (degrees).
        previous: f64,
    },
    /// A step between angles above [`MAX_STEP_DEG`].
    StepTooWide {
        /// The line that ends the step.
        line: usize,
        /// The step (degrees).
        step: f64,
    },
    /// An angle above 90 degrees.
    AboveNinety {
        /// The line.
        line: usize,
        /// The angle (degrees).
        theta: f64,
    },
    /// The table ends before 90 degrees with a non-zero D (a cut-off must end with D = 0).
    EndsEarly {
        /// The last angle (degrees).
        theta: f64,
        /// D there.
        value: f64,
    },
    /// D is zero everywhere: no projected area to normalize.
    AllZero,
}

impl fmt::Display for TableError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TableError::Header { found } => write!(f, "the header is {found:?}; expected {HEADER:?}"),
            TableError::Row { line, text } => {
                write!(f, "line {line}: {text:?} is not two numbers theta_m_deg,D separated by a comma")
            }
            TableError::TooFewRows { rows } => write!(f, "{rows} rows; a table needs at least {MIN_ROWS}"),
            TableError::NotFinite { line, column, value } => write!(f, "line {line}: {column} = {value} is not finite"),
            TableError::Negative { line, value } => write!(f, "line {line}: D = {value} is negative; D must be >= 0"),
            TableError::FirstAngle { theta } => {
                write!(f, "the first angle is {theta} deg; the table must start at theta_m_deg = 0")
            }
            TableError::NotIncreasing { line, theta, previous } => write!(
                f,
                "line {line}: theta_m_deg = {theta} does not increase (the line before has {previous}); angles must \
                 strictly increase"
            ),
            TableError::StepTooWide { line, step } => {
                write!(f, "line {line}: a step of {step} deg; steps may be at most {MAX_STEP_DEG} deg")
            }
            TableError::AboveNinety { line, theta } => {
                write!(f, "line {line}: theta_m_deg = {theta} is above 90; normals are in [0, 90] deg")
            }
            TableError::EndsEarly { theta, value } => write!(
                f,
                "the table ends at {theta} deg with D = {value}; it must reach 90 deg, or end earlier with D = 0 (a \
                 cut-off)"
            ),
            TableError::AllZero => write!(f, "D is 0 everywhere; a table needs a positive projected area"),
        }
    }
}

impl std::error::Error for TableError {}

/// The rows `(line, theta_m_deg, D)` of a CSV table: comment lines (`#`) and blank lines are
/// skipped, the first other line must be [`HEADER`].
pub fn parse_csv(text: &str) -> Result<Vec<(usize, f64, f64)>, TableError> {
    let mut lines =
        text.lines().enumerate().map(|(i, l)| (i + 1, l.trim())).filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    match lines.next() {
        Some((_, header)) if header.replace(' ', "") == HEADER => {}
        Some((_, header)) => return Err(TableError::Header { found: header.to_string() }),
        None => return Err(TableError::Header { found: String::new() }),
    }
    lines
        .map(|(line, l)| {
            let bad = || TableError::Row { line, text: l.to_string() };
            let mut fields = l.split(',').map(|x| x.trim().parse::<f64>());
            match (fields.next(), fields.next(), fields.next()) {
                (Some(Ok(theta)), Some(Ok(d)), None) => Ok((line, theta, d)),
                _ => Err(bad()),
            }
        })
        .collect()
}

/// Checks the rows `(line, theta_m_deg, D)` (§1.7): finite, `D >= 0`, angles from 0, strictly
/// increasing, up to 90 degrees by at most [`MAX_STEP_DEG`], or to a cut-off where D is 0, and
/// not all zero. The first fault found, in that order, row by row.
pub fn check(rows: &[(usize, f64, f64)]) -> Result<(), TableError> {
    if rows.len() < MIN_ROWS {
        return Err(TableError::TooFewRows { rows: rows.len() });
    }
    for (i, &(line, theta, d)) in rows.iter().enumerate() {
        if !theta.is_finite() {
            return Err(TableError::NotFinite { line, column: "theta_m_deg", value: theta });
        }
        if !d.is_finite() {
            return Err(TableError::NotFinite { line, column: "D", value: d });
        }
        if d < 0.0 {
            return Err(TableError::Negative { line, value: d });
        }
        if i == 0 {
            if theta != 0.0 {
                return Err(TableError::FirstAngle { theta });
            }
            continue;
        }
        let previous = rows[i - 1].1;
        if theta <= previous {
            return Err(TableError::NotIncreasing { line, theta, previous });
        }
        if theta > 90.0 {
            return Err(TableError::AboveNinety { line, theta });
        }
        if theta - previous > MAX_STEP_DEG {
            return Err(TableError::StepTooWide { line, step: theta - previous });
        }
    }
    let &(_, theta, d) = rows.last().expect("at least MIN_ROWS rows");
    if theta < 90.0 && d != 0.0 {
        return Err(TableError::EndsEarly { theta, value: d });
    }
    if rows.iter().all(|r| r.2 == 0.0) {
        return Err(TableError::AllZero);
    }
    Ok(())
}
