//! What a run needs before it starts: its thread count, its peak memory and the bytes it writes,
//! estimated from the config alone and held against the memory the process may use and the
//! room on the output volume (docs/reliability.md, "Memory" and "Disk"), so that a config that
//! cannot finish is refused in one line before any work.

use std::path::Path;

use anyhow::{Result, bail};

use crate::engine::detector::Detector;
use crate::setup::config::{Config, DEFAULT_MAX_ORDER};

/// The most worker threads a run may ask for. Outputs do not depend on the thread count, and
/// starting many more threads than cores only costs time (`--threads 100000` took minutes).
pub const MAX_THREADS: usize = 1024;

/// The share of the memory available to the process that a run may plan to use by default
/// (`--max-memory` sets the limit itself): the rest is left to the system and to the
/// estimate's own error.
pub const DEFAULT_MEMORY_SHARE: f64 = 0.8;

/// Bytes per row of `lobes.csv` assumed by the estimate (rows of the shipped configs take 110
/// to 150 bytes).
const CSV_ROW_BYTES: u64 = 160;

/// Bytes of the process before any detector: the binary, the allocator, the threads' stacks.
const BASELINE_BYTES: u64 = 16 << 20;

/// Bytes per row of `lobes.csv` assumed by the disk estimate: the rows of the quickstart at
/// 1.5 million photons take 226 bytes on average and 256 at most (a lit bin's numbers carry
/// 17 significant digits).
const DISK_ROW_BYTES: u64 = 256;

/// Bytes per case of `run.json` assumed by the disk estimate (a case takes about 1 kB).
const RECORD_BYTES_PER_CASE: u64 = 4 << 10;

/// Bytes per order slot of a case in `summary.csv`: a row per hemisphere and channel.
const SUMMARY_BYTES_PER_SLOT: u64 = 6 * DISK_ROW_BYTES;

/// A run's estimated peak memory, by part.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MemoryEstimate {
    /// Order slots per detector: `detector.max_order + 1`.
    pub slots: u64,
    /// Detectors held at once: every case's, and two per thread (the round being walked and
    /// the one waiting to be merged).
    pub detectors: u64,
    /// Bytes of one detector with every slot reached.
    pub detector_bytes: u64,
    /// Bytes of the text of `lobes.csv`, held while it is written.
    pub table_bytes: u64,
}

impl MemoryEstimate {
    /// The estimate for `config` on `threads` threads. Slots are added as orders are reached
    /// and never beyond `detector.max_order` ([`DEFAULT_MAX_ORDER`] when the config leaves it out), so this is an
    /// upper bound of what the detectors hold; docs/reliability.md states how close it is to
    /// the measured peak.
    pub fn of(config: &Config, threads: usize) -> Self {
        let d = &config.detector;
        let slots = u64::from(d.max_order.unwrap_or(DEFAULT_MAX_ORDER)) + 1;
        let bins = (d.cos_theta_bins * d.phi_bins) as u64;
        let (per_bin, channels) =
            if config.is_rgb() { (Detector::<3>::bytes_per_bin(), 3) } else { (Detector::<1>::bytes_per_bin(), 1) };
        // Both hemispheres of every slot.
        let detector_bytes = slots.saturating_mul(2 * bins).saturating_mul(per_bin);
        let cases = config.cases();
        let rows = cases.saturating_mul(slots).saturating_mul(2 * bins * channels);
        Self {
            slots,
            detectors: cases.saturating_add(2 * threads as u64),
            detector_bytes,
            table_bytes: rows.saturating_mul(CSV_ROW_BYTES),
        }
    }

    /// The estimated peak in bytes.
    pub fn bytes(&self) -> u64 {
        self.detectors
            .saturating_mul(self.detector_bytes)
            .saturating_add(self.table_bytes)
            .saturating_add(BASELINE_BYTES)
    }
}

/// The most bytes a run writes into its output directory at once, by part: its tables, and its
/// checkpoint twice (a new one is written beside the last before it replaces it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiskEstimate {
    /// `lobes.csv`, `summary.csv` and `run.json`, with every order slot reached in both
    /// hemispheres.
    pub table_bytes: u64,
    /// One `checkpoint.bin` (or `shard.bin`) with every order slot reached.
    pub checkpoint_bytes: u64,
}

impl DiskEstimate {
    /// The estimate for `config`: an upper bound, as [`MemoryEstimate::of`] (slots up to
    /// `detector.max_order`, [`DEFAULT_MAX_ORDER`] when the config leaves it out).
    pub fn of(config: &Config) -> Self {
        let d = &config.detector;
        let slots = u64::from(d.max_order.unwrap_or(DEFAULT_MAX_ORDER)) + 1;
        let bins = (d.cos_theta_bins * d.phi_bins) as u64;
        let (per_bin, channels) = if config.is_rgb() {
            (Detector::<3>::saved_bytes_per_bin(), 3)
        } else {
            (Detector::<1>::saved_bytes_per_bin(), 1)
        };
        // Per case: both hemispheres of every slot.
        let slot_bins = slots.saturating_mul(2 * bins);
        let cases = config.cases();
        let rows = cases.saturating_mul(slot_bins).saturating_mul(channels);
        let records = RECORD_BYTES_PER_CASE.saturating_add(slots.saturating_mul(SUMMARY_BYTES_PER_SLOT));
        Self {
            table_bytes: rows.saturating_mul(DISK_ROW_BYTES).saturating_add(cases.saturating_mul(records)),
            checkpoint_bytes: cases.saturating_mul(slot_bins).saturating_mul(per_bin),
        }
    }

    /// The estimate in bytes: the tables and two checkpoints.
    pub fn bytes(&self) -> u64 {
        self.table_bytes.saturating_add(self.checkpoint_bytes.saturating_mul(2))
    }
}

/// Checks, before any work, that the volume of `dir` (which exists) has room for what a run of
/// `config` writes there ([`DiskEstimate`]). Returns the estimate and the bytes free (`None`
/// if the volume cannot tell), for the run to print.
pub fn check_disk(config: &Config, dir: &Path) -> Result<(DiskEstimate, Option<u64>)> {
    let estimate = DiskEstimate::of(config);
    let free = free_space(dir);
    if let Some(free) = free {
        check_room(config, &estimate, free, dir)?;
    }
    Ok((estimate, free))
}

/// Refuses a run whose estimated writes exceed the `free` bytes of the volume of `dir`, in one
/// line naming the fields that size them.
fn check_room(config: &Config, estimate: &DiskEstimate, free: u64, dir: &Path) -> Result<()> {
    if estimate.bytes() <= free {
        return Ok(());
    }
    let d = &config.detector;
    bail!(
        "the run writes up to {} into {} but its volume has {} free: lobes.csv and two checkpoints of {} cases x \
         {} x {} bins (detector.cos_theta_bins x detector.phi_bins) x {} order slots (detector.max_order = {}); \
         free space, choose another --out, lower the bins or detector.max_order, or sweep fewer cases",
        gigabytes(estimate.bytes()),
        dir.display(),
        gigabytes(free),
        config.cases(),
        d.cos_theta_bins,
        d.phi_bins,
        u64::from(d.max_order.unwrap_or(DEFAULT_MAX_ORDER)) + 1,
        d.max_order.unwrap_or(DEFAULT_MAX_ORDER)
    )
}

/// The bytes an unprivileged process may still write on the volume of `dir`, if it can tell.
fn free_space(dir: &Path) -> Option<u64> {
    let stat = rustix::fs::statvfs(dir).ok()?;
    Some(stat.f_bavail.saturating_mul(stat.f_frsize))
}

/// How much memory the process may use, and where that figure comes from.
#[derive(Clone, Debug, PartialEq)]
pub struct MemoryLimit {
    pub bytes: u64,
    /// `--max-memory`, or the share of which allowance (cgroup, Slurm, the machine).
    pub source: String,
}

impl MemoryLimit {
    /// `--max-memory` if given, else [`DEFAULT_MEMORY_SHARE`] of the least of the memory the
    /// machine has available now, the process's cgroup allows and its Slurm allocation holds;
    /// `None` if none of them can be read (then nothing is refused).
    pub fn of(max_memory: Option<u64>) -> Option<Self> {
        if let Some(bytes) = max_memory {
            return Some(Self { bytes, source: "--max-memory".into() });
        }
        let allowances = [
            (available_memory(), "the memory available on this machine"),
            (cgroup_memory(), "the process's cgroup memory limit"),
            (slurm_memory(), "the Slurm job's memory allocation"),
        ];
        let (bytes, source) =
            allowances.into_iter().filter_map(|(bytes, source)| Some((bytes?, source))).min_by_key(|(b, _)| *b)?;
        let share = (bytes as f64 * DEFAULT_MEMORY_SHARE) as u64;
        Some(Self { bytes: share, source: format!("{:.0}% of {source}", DEFAULT_MEMORY_SHARE * 100.0) })
    }
}

/// The thread count a run will use: `threads`, checked, or all cores.
pub fn thread_count(threads: Option<usize>) -> Result<usize> {
    match threads {
        Some(0) => bail!("`--threads` = 0 is not allowed: at least 1 thread"),
        Some(n) if n > MAX_THREADS => bail!(
            "`--threads` = {n} is not allowed: at most {MAX_THREADS} (outputs do not depend on the thread count; \
             this machine has {} cores)",
            cores()
        ),
        Some(n) => Ok(n),
        None => Ok(cores()),
    }
}

/// Checks, before any work, that a run of `config` on `threads` threads can finish: the thread
/// count is within [`MAX_THREADS`] and the estimated peak memory fits under the limit
/// ([`MemoryLimit::of`] `max_memory`). The error names the fields to change. Returns the
/// estimate and the limit, for the run to print.
pub fn check_resources(
    config: &Config,
    threads: Option<usize>,
    max_memory: Option<u64>,
) -> Result<(MemoryEstimate, Option<MemoryLimit>)> {
    let threads = thread_count(threads)?;
    let estimate = MemoryEstimate::of(config, threads);
    let limit = MemoryLimit::of(max_memory);
    if let Some(limit) = &limit
        && estimate.bytes() > limit.bytes
    {
        let d = &config.detector;
        bail!(
            "the run needs about {} but {} allows {}: {} cases x {} x {} bins (detector.cos_theta_bins x \
             detector.phi_bins) x {} order slots (detector.max_order = {}) x {} channels, held for every case and \
             {threads} threads (--threads), plus lobes.csv; lower the bins or detector.max_order, sweep fewer cases \
             or split the sweep into several configs, or raise --max-memory",
            gigabytes(estimate.bytes()),
            limit.source,
            gigabytes(limit.bytes),
            config.cases(),
            d.cos_theta_bins,
            d.phi_bins,
            estimate.slots,
            d.max_order.unwrap_or(DEFAULT_MAX_ORDER),
            if config.is_rgb() { 3 } else { 1 }
        );
    }
    Ok((estimate, limit))
}

/// `bytes` for people: `1.35 GB`, or `48 MB` below a gigabyte.
pub fn gigabytes(bytes: u64) -> String {
    if bytes >= 1_000_000_000 {
        format!("{:.2} GB", bytes as f64 / 1e9)
    } else {
        format!("{:.0} MB", bytes as f64 / 1e6)
    }
}

/// Parses `--max-memory`: a number of bytes with an optional unit, `K`, `M`, `G` or `T`
/// (powers of 1024, optionally followed by `B` or `iB`), e.g. `8G`, `512MiB`, `2000000000`.
pub fn parse_size(text: &str) -> Result<u64, String> {
    let t = text.trim();
    let digits = t.find(|c: char| !(c.is_ascii_digit() || c == '.')).unwrap_or(t.len());
    let (number, unit) = t.split_at(digits);
    let unit = unit.trim().to_ascii_uppercase();
    let unit = unit.trim_end_matches("IB").trim_end_matches('B');
    let scale: u64 = match unit {
        "" => 1,
        "K" => 1 << 10,
        "M" => 1 << 20,
        "G" => 1 << 30,
        "T" => 1 << 40,
        _ => return Err(format!("{text:?} is not a size: a number with an optional unit K, M, G or T (e.g. 8G)")),
    };
    let value: f64 =
        number.parse().map_err(|_| format!("{text:?} is not a size: a number with an optional unit K, M, G or T"))?;
    let bytes = value * scale as f64;
    if !(bytes >= 1.0 && bytes < u64::MAX as f64) {
        return Err(format!("{text:?} is not allowed: at least 1 byte and below 16 EiB"));
    }
    Ok(bytes as u64)
}

/// The process's peak resident memory so far (`VmHWM` of `/proc/self/status`), where there is one.
pub fn peak_memory() -> Option<u64> {
    proc_field("/proc/self/status", "VmHWM:")
}

fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, usize::from)
}

/// A `Name: <kB> kB` field of a `/proc` file, in bytes.
fn proc_field(path: &str, name: &str) -> Option<u64> {
    let text = std::fs::read_to_string(path).ok()?;
    let line = text.lines().find(|l| l.starts_with(name))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// `MemAvailable` of `/proc/meminfo`.
fn available_memory() -> Option<u64> {
    proc_field("/proc/meminfo", "MemAvailable:")
}

/// The memory the process's cgroup may still use: `memory.max` less `memory.current` (cgroup
/// v2), or `memory.limit_in_bytes` less `memory.usage_in_bytes` (v1); `None` without a limit.
fn cgroup_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/self/cgroup").ok()?;
    let read = |path: String| -> Option<u64> { std::fs::read_to_string(path).ok()?.trim().parse().ok() };
    for line in text.lines() {
        let mut parts = line.splitn(3, ':');
        let (_, controllers, path) = (parts.next()?, parts.next()?, parts.next()?);
        let (limit, usage) = if controllers.is_empty() {
            let dir = format!("/sys/fs/cgroup{path}");
            (read(format!("{dir}/memory.max")), read(format!("{dir}/memory.current")))
        } else if controllers.split(',').any(|c| c == "memory") {
            let dir = format!("/sys/fs/cgroup/memory{path}");
            (read(format!("{dir}/memory.limit_in_bytes")), read(format!("{dir}/memory.usage_in_bytes")))
        } else {
            continue;
        };
        // v2 writes `max` (not a number) and v1 a huge number for no limit.
        if let Some(limit) = limit.filter(|&l| l < 1 << 60) {
            return Some(limit.saturating_sub(usage.unwrap_or(0)));
        }
    }
    None
}

/// The Slurm job's memory per node in bytes: `SLURM_MEM_PER_NODE` (MB), or
/// `SLURM_MEM_PER_CPU` (MB) times `SLURM_CPUS_ON_NODE`.
fn slurm_memory() -> Option<u64> {
    let var = |name| std::env::var(name).ok()?.trim().parse::<u64>().ok();
    let mb = var("SLURM_MEM_PER_NODE").or_else(|| Some(var("SLURM_MEM_PER_CPU")? * var("SLURM_CPUS_ON_NODE")?))?;
    Some(mb.saturating_mul(1 << 20))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 36 item 16: a run whose estimated writes exceed the room on the volume is refused
    /// in one line naming the sizes and the fields to change; one that fits is not.
    #[test]
    fn a_run_without_room_on_its_volume_is_refused() {
        let config = Config::parse(
            "paths = 1000\n[surface]\nalpha = [0.3, 0.6]\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = 30\n\
             [detector]\ncos_theta_bins = 8\nphi_bins = 16\nmax_order = 3\n",
        )
        .unwrap();
        let estimate = DiskEstimate::of(&config);
        let dir = Path::new("/scratch/out");
        assert!(check_room(&config, &estimate, estimate.bytes(), dir).is_ok());
        let e = format!("{:#}", check_room(&config, &estimate, estimate.bytes() - 1, dir).unwrap_err());
        assert!(!e.contains('\n'), "{e}");
        for words in ["into /scratch/out but its volume has", "2 cases x 8 x 16 bins", "4 order slots", "--out"] {
            assert!(e.contains(words), "{words:?} not in: {e}");
        }
    }

    #[test]
    fn sizes_read_with_their_units() {
        assert_eq!(parse_size("2000"), Ok(2000));
        assert_eq!(parse_size("8G"), Ok(8 << 30));
        assert_eq!(parse_size("512MiB"), Ok(512 << 20));
        assert_eq!(parse_size("1.5 GB"), Ok(3 << 29));
        assert_eq!(parse_size("64k"), Ok(64 << 10));
        for bad in ["", "G", "-1G", "8X", "0", "1e30", "nan"] {
            assert!(parse_size(bad).is_err(), "{bad:?} was accepted");
        }
    }
}
