"""smithwalk: a virtual gonioreflectometer for the Smith microsurface.

Monte Carlo random walks on the statistical Smith microsurface (Heitz et al. 2016, Hammon 2017),
measured like a gonioreflectometer: angular histograms of the escaping energy for every bounce
order, in reflection and transmission, each bin with its standard error.

Functions
---------
run(config, *, paths=None, seed=None, threads=None, progress=False)
    Walk every case of a configuration (TOML text, a TOML file or a dict); returns a
    :class:`RunResult`.
load(path)
    Read a run directory written by ``smithwalk run`` or :meth:`RunResult.save`.
columns(file=None)
    The columns of the run directory's tables: name, unit and meaning.

Classes
-------
RunResult
    Lobes as numpy arrays shaped ``(case, order, hemisphere, cos_bin, phi_bin[, channel])``,
    bin edges, order labels, cases, the summary table; ``compare`` and ``save``.
Comparison
    The result of :meth:`RunResult.compare`: the ``compare.csv`` table and the models' lobes.

The configuration schema, the conventions and the CSV columns are those of the command line
(see the repository's README.md); ``docs/python.md`` has a tour of this package.
"""

from __future__ import annotations

import csv
import io
import json
import numbers
import os
import tempfile
from pathlib import Path

import numpy as np

from . import _native

__all__ = ["run", "load", "columns", "RunResult", "Comparison", "MODELS", "HEMISPHERES", "CHANNELS"]

__version__ = _native.__version__

#: The comparison models, as the command line names them.
MODELS = tuple(_native.model_names())
#: Labels of the hemisphere axis: ``R`` is the side the light came from, ``T`` the other.
HEMISPHERES = ("R", "T")
#: Labels of the channel axis of RGB runs.
CHANNELS = ("r", "g", "b")

# The run directory's files and columns come from the extension (the crate's io::schema).
_RUN_FILES, _COMPARE_FILES = _native.files()
# What follows a model's name in its standard-error column of models.csv ("<model>_stderr").
_STDERR = _native.columns()["models.csv"][-1][0].replace("<model>", "")


def columns(file=None):
    """The columns of the run directory's tables, as the command line writes them.

    Parameters
    ----------
    file : str, optional
        A table's file name (``"lobes.csv"``, ``"summary.csv"``, ``"models.csv"``,
        ``"compare.csv"``); all tables when omitted.

    Returns
    -------
    list of (name, unit, meaning), or dict of such lists per file name
        Each table's columns in order. ``channel`` is written by RGB runs only; in
        ``models.csv``, ``<model>`` and ``<model>_stderr`` stand for one pair of columns per
        model compared.
    """
    tables = _native.columns()
    if file is None:
        return tables
    if file not in tables:
        raise ValueError(f"file = {file!r} is not allowed: one of {', '.join(tables)}")
    return tables[file]


def _config_source(config):
    """The config as (text, kind) for the native parser: a dict, a path or TOML text."""
    if isinstance(config, dict):
        return config, "dict"
    if isinstance(config, os.PathLike):
        return os.fspath(config), "path"
    if isinstance(config, str):
        # Every TOML configuration has a key = value; a file name has neither "=" nor a newline.
        if "=" in config or "\n" in config:
            return config, "toml"
        return config, "path"
    raise TypeError(
        f"config must be a TOML string, a path or a dict, not {type(config).__name__}"
    )


def _unsigned(name, value, *, minimum=0):
    """An optional integer argument from `minimum` to 2^64 - 1 (Python's or numpy's), checked
    with the command line's wording."""
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"`{name}` must be an integer, not {type(value).__name__}")
    value = int(value)
    if value < minimum:
        raise ValueError(f"`{name}` = {value} is not allowed: an integer >= {minimum}")
    if value > 2**64 - 1:
        raise ValueError(f"`{name}` = {value} is not allowed: an integer from {minimum} to 2^64 - 1")
    return value


def _table(data: bytes):
    """A CSV table as a pandas DataFrame, or as a dict of numpy arrays without pandas.

    Numbers are parsed exactly (``float_precision="round_trip"``), so they equal the values
    the CSV was written from.
    """
    try:
        import pandas as pd
    except ImportError:
        pd = None
    if pd is not None:
        # pandas 3 parses floats exactly by default and deprecates the option.
        exact = {} if int(pd.__version__.split(".")[0]) >= 3 else {"float_precision": "round_trip"}
        return pd.read_csv(io.BytesIO(data), keep_default_na=False, **exact)
    rows = list(csv.reader(io.StringIO(data.decode())))
    header, body = rows[0], rows[1:]
    return {name: _column([r[i] for r in body]) for i, name in enumerate(header)}


def _column(values):
    """A CSV column as an int64, float64, bool or str array, whichever holds every value."""
    if values and all(v in ("true", "false") for v in values):
        return np.array([v == "true" for v in values])
    for kind in (int, float):
        try:
            return np.array([kind(v) for v in values])
        except ValueError:
            pass
    return np.array(values, dtype=str)


class Comparison:
    """A run compared with analytic models (the result of :meth:`RunResult.compare`).

    Attributes
    ----------
    models : tuple of str
        The models compared, in the order asked for.
    table : pandas.DataFrame or dict of numpy.ndarray
        ``compare.csv``: per case, model, order and hemisphere the two-sample chi-square test
        of the measured lobe against the model's (``chi2``, ``dof``, ``p_value``), the lobes'
        relative L1 and L2 differences and both albedos with standard errors.
    lobes : dict of str to dict of numpy.ndarray
        Per model name the model's lobes from ``models.csv`` (its columns ``<model>`` and
        ``<model>_stderr``, row for row beside ``lobes.csv``): ``energy``, ``energy_stderr``
        (0 for closed-form models) and ``bsdf`` (``energy`` over the bin's projected solid
        angle), float64 arrays shaped like the run's (``(case, order, hemisphere, cos_bin,
        phi_bin[, channel])``). Cases, orders and channels a model does not give are zero; a
        model that gives no lobe at all (``single`` with ``max_order = 1``) is absent.
    report : str
        The text ``smithwalk compare`` prints: the worst lobes per model.
    """

    def __init__(self, models, files, lobes, report):
        self.models = tuple(models)
        self._files = files
        self.table = _table(files["compare.csv"])
        self.lobes = lobes
        self.report = report

    def __getitem__(self, model):
        """The lobes of one model, as in :attr:`lobes`."""
        return self.lobes[model]

    def __repr__(self):
        return f"Comparison(models={list(self.models)!r})"


class RunResult:
    """The measurements of a run: per-order lobes as numpy arrays, albedos, cases.

    Returned by :func:`run` and :func:`load`; not meant to be built directly.

    Attributes
    ----------
    energy : numpy.ndarray of float64
        Fraction of the incident energy leaving through each bin, ``E[H/N]`` (the integral of
        ``f |cos theta|`` over the bin), shaped ``(case, order, hemisphere, cos_bin, phi_bin)``,
        with a last ``channel`` axis of 3 for RGB runs. Order 0 is all orders together;
        hemisphere 0 (``R``) is the side the light came from, 1 (``T``) the other side (zero
        for materials that do not transmit). Orders a case never reached are zero.
    energy_stderr : numpy.ndarray of float64
        The standard error of each ``energy`` (per-photon second moments).
    count : numpy.ndarray of uint64
        Photons that put energy into each bin.
    bsdf : numpy.ndarray of float64
        ``energy`` over the bin's projected solid angle: the cosine-weighted bin average of
        the BSDF, in 1/sr.
    bsdf_stderr : numpy.ndarray of float64
        Its standard error.
    cos_edges : numpy.ndarray
        The ``cos_bins + 1`` edges of the cos bins in ``|cos theta|`` (theta from the
        macro-normal; in ``T`` the directions have negative ``cos theta``).
    phi_edges_deg : numpy.ndarray
        The ``phi_bins + 1`` edges of the phi bins, in degrees from the incident azimuth (the
        mirror direction is at 180).
    projected_solid_angle : numpy.ndarray
        Per cos bin, the projected solid angle of one of its bins (``bsdf = energy / this``).
    orders : tuple of str
        Labels of the order axis: ``"all"``, ``"1"``, ``"2"``, ... and ``"K+"`` for the slot
        that holds every order from ``detector.max_order = K`` on.
    folded : numpy.ndarray of bool
        Per order slot, whether it is the folded ``"K+"`` slot.
    hemispheres : tuple of str
        ``("R", "T")``.
    channels : tuple of str or None
        ``("r", "g", "b")`` for RGB runs, ``None`` otherwise (no channel axis).
    cases : list of dict
        Per case its parameters (``ndf``, ``alpha_x``, ``alpha_y``, ``material``,
        ``theta_i_deg``, ...) and its ``energy`` balance, as in ``run.json``.
    config : dict
        The resolved configuration (overrides applied), as in ``run.json``.
    info : dict
        ``run.json`` without its cases: version, seed, paths, threads, wall time, throughput.
    summary : pandas.DataFrame or dict of numpy.ndarray
        ``summary.csv``: per case, order and hemisphere the albedo and its standard error, and
        the absorbed and lost energy (a dict of column arrays when pandas is not installed).
    comparison : Comparison or None
        The last comparison with models (:meth:`compare`, or the config's ``[compare]``).
    path : pathlib.Path or None
        The run directory this result was loaded from or last saved to.
    """

    hemispheres = HEMISPHERES

    def __init__(self, *, info, lobes, summary_csv, native=None, path=None):
        self._native = native
        self._summary_csv = summary_csv
        self.path = Path(path) if path is not None else None
        self.comparison = None
        self.cases = info.pop("cases")
        self.config = info["config"]
        self.info = info
        detector = self.config.get("detector", {})
        self.cos_edges, self.phi_edges_deg, self.projected_solid_angle = _native.grid(
            detector.get("cos_theta_bins", 32), detector.get("phi_bins", 64)
        )
        for name, values in lobes.items():
            setattr(self, name, values)
        slots = self.energy.shape[1]
        max_order = detector.get("max_order")
        self.folded = np.array([k == max_order for k in range(slots)])
        self.orders = tuple(
            "all" if k == 0 else f"{k}+" if k == max_order else str(k) for k in range(slots)
        )
        self.channels = CHANNELS if self.energy.ndim == 6 else None
        self.summary = _table(summary_csv)

    @classmethod
    def _of_native(cls, native):
        info = json.loads(native.run_json())
        return cls(info=info, lobes=native.lobes(), summary_csv=native.summary_csv(), native=native)

    def __repr__(self):
        shape = "x".join(map(str, self.energy.shape))
        where = f", path={str(self.path)!r}" if self.path else ""
        return f"RunResult({len(self.cases)} cases, lobes {shape}, orders {list(self.orders)}{where})"

    def _files_into(self, directory):
        """Writes (or links, for a loaded run) the run's files into `directory`."""
        if self._native is not None:
            self._native.save(directory)
            return
        for name in _RUN_FILES:
            source = (self.path / name).resolve()
            try:
                os.symlink(source, Path(directory) / name)
            except OSError:
                _native.write_files(directory, [(name, source.read_bytes())])

    def compare(self, models=None, *, paths=None, threads=None):
        """Compare the measured lobes with analytic models, as ``smithwalk compare`` does.

        Parameters
        ----------
        models : sequence of str, optional
            Model names from :data:`MODELS`: ``single``, ``hammon-fit``, ``heitz-nee``,
            ``exact-position-free``, ``wang-correlated``, ``wang-uncorrelated``,
            ``cui2023-released``, ``kulla-conty``, ``turquin``, ``fdez-aguera``, ``materialx``,
            ``lee2018``. Default: all.
        paths : int, optional
            Photons per case for the Monte Carlo models (default: the run's).
        threads : int, optional
            Worker threads (default: all cores).

        Returns
        -------
        Comparison
            The ``compare.csv`` table, the models' lobes as arrays shaped like the run's, and
            the report. It is also kept in :attr:`comparison`, and :meth:`save` writes it.

        Raises
        ------
        ValueError
            For an unknown model name, ``paths < 2`` or ``threads = 0``.
        """
        models = list(MODELS if models is None else ([models] if isinstance(models, str) else models))
        with tempfile.TemporaryDirectory(prefix="smithwalk-compare-") as tmp:
            self._files_into(tmp)
            report = _native.compare(
                tmp, models, _unsigned("paths", paths, minimum=2), _unsigned("threads", threads, minimum=1)
            )
            files = {name: (Path(tmp) / name).read_bytes() for name in _COMPARE_FILES}
            lobes = _native.read_models(tmp)
        self.comparison = Comparison(models, files, lobes, report)
        return self.comparison

    def save(self, path):
        """Write the run directory: the files ``smithwalk run`` writes, byte for byte.

        ``lobes.csv``, ``summary.csv`` and ``run.json`` (written atomically by the command
        line's own writer), and ``models.csv`` and ``compare.csv`` after a comparison.

        Parameters
        ----------
        path : str or os.PathLike
            The directory, created if need be.

        Returns
        -------
        list of pathlib.Path
            The files written.
        """
        path = Path(path)
        if self._native is not None:
            written = [Path(p) for p in self._native.save(path)]
        else:
            files = [(name, (self.path / name).read_bytes()) for name in _RUN_FILES]
            written = [Path(p) for p in _native.write_files(path, files)]
        if self.comparison is not None:
            files = list(self.comparison._files.items())
            written += [Path(p) for p in _native.write_files(path, files)]
        self.path = path
        return written


def run(config, *, paths=None, seed=None, threads=None, progress=False):
    """Walk every case of a configuration, as ``smithwalk run`` does.

    The walk runs with the GIL released; Ctrl-C stops it after the current round of chunks
    (a fraction of a second) and raises ``KeyboardInterrupt``. The same config and seed give
    bit-identical numbers for any thread count, and the same as the command line.

    Parameters
    ----------
    config : str, os.PathLike or dict
        TOML text, the path of a TOML file, or a dict with the same schema (the keys and
        tables of the TOML file; numpy scalars and arrays are accepted as values). A ``str``
        with neither ``=`` nor a newline is taken as a path.
    paths : int, optional
        Photons per case (overrides ``paths``).
    seed : int, optional
        Random seed (overrides ``seed``).
    threads : int, optional
        Worker threads (default: all cores). The results do not depend on it.
    progress : bool, default False
        Draw a progress bar on the terminal (stderr).

    Returns
    -------
    RunResult
        Lobes, albedos and cases. With a ``[compare]`` table in the config, the comparison
        has run too (:attr:`RunResult.comparison`), as with the command line.

    Raises
    ------
    ValueError
        For an invalid configuration, with the command line's message (the field, the value
        and what is allowed).
    OSError
        When the config file cannot be read.
    KeyboardInterrupt
        On Ctrl-C.

    Examples
    --------
    >>> import smithwalk
    >>> r = smithwalk.run('''
    ... paths = 100_000
    ... [surface]
    ... alpha = [0.25, 0.5]
    ... [material]
    ... kind = "conductor"
    ... [incident]
    ... theta_deg = 60
    ... [detector]
    ... max_order = 3
    ... ''')
    >>> r.energy.shape, r.orders
    ((2, 4, 2, 32, 64), ('all', '1', '2', '3+'))
    """
    source, kind = _config_source(config)
    native = _native.run(
        source,
        kind,
        _unsigned("paths", paths, minimum=2),
        _unsigned("seed", seed),
        _unsigned("threads", threads, minimum=1),
        bool(progress),
    )
    result = RunResult._of_native(native)
    compare = result.config.get("compare")
    if compare:
        result.compare(compare["models"], paths=compare.get("paths"), threads=threads)
    return result


def load(path):
    """Read a run directory written by ``smithwalk run`` or :meth:`RunResult.save`.

    Parameters
    ----------
    path : str or os.PathLike
        The directory with ``run.json``, ``lobes.csv`` and ``summary.csv`` (and, after a
        comparison, ``models.csv``, ``compare.csv`` and their seal ``compare.json``).

    Returns
    -------
    RunResult
        The same arrays as the run that wrote the directory.

    Raises
    ------
    ValueError
        When a file is missing or not a table of a run, or when ``models.csv`` and
        ``compare.csv`` are not the ones ``compare.json`` records for this run.
    """
    path = Path(path)
    config = json.loads(_native.read_config(path))
    info = json.loads((path / "run.json").read_text())
    detector = config["detector"]
    cos_bins, phi_bins = detector["cos_theta_bins"], detector["phi_bins"]
    cases = len(info["cases"])
    lobes = _native.read_lobes(path / "lobes.csv", cases, cos_bins, phi_bins)
    result = RunResult(
        info=info, lobes=lobes, summary_csv=(path / "summary.csv").read_bytes(), path=path
    )
    # Any of the comparison's files: read_models refuses a set that compare.json does not seal.
    if any((path / name).exists() for name in _COMPARE_FILES):
        lobes = _native.read_models(path)
        files = {name: (path / name).read_bytes() for name in _COMPARE_FILES}
        models = _model_names(files["models.csv"])
        result.comparison = Comparison(models, files, lobes, report="")
    return result


def _model_names(models_csv: bytes):
    """The models of a ``models.csv``, in the order compared: each column ``<name>`` that has a
    column ``<name>_stderr``."""
    header = next(csv.reader([models_csv.split(b"\n", 1)[0].decode()]))
    return [name for name in header if f"{name}{_STDERR}" in header]
from . import bsdf  # noqa: E402  (smithwalk.bsdf: the BSDF for renderers)
