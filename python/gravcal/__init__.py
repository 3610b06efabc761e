"""gravcal: IMU calibration with gravity as the only reference, from Python.

NumPy in and out, over the same C++ library as the ``gravcal`` command:
a calibration made here is the calibration JSON the CLI writes, number for
number. Configuration is a YAML file (``configs/*.yaml``), a dict with the
same keys, or keyword arguments with those keys (``gravity=9.81744``).
Every failure raises :class:`gravcal.Error` (a ``ValueError``) with the
CLI's one-line message. Long calls release the GIL, so threads help.

>>> import gravcal
>>> truth, log = gravcal.simulate(config="configs/twelve_position.yaml", seed=7)
>>> cal = gravcal.calibrate(log, config="configs/twelve_position.yaml")
>>> accel_si, _ = cal.apply(log.accel)

See docs/python.md.
"""

import json as _json
import math as _math
import os as _os
import warnings as _warnings

import numpy as _np

from . import _gravcal
from ._gravcal import Error, Log

__version__ = _gravcal.__version__

__all__ = [
    "Error", "Log", "Calibration", "Result", "BatchResult", "BatchResults", "Config", "config",
    "read_log", "log", "calibrate", "simulate", "batch", "noise", "discover", "plan", "check", "export",
    "Recorder", "config_keys", "__version__",
    "thermal_model", "thermal_evaluate",
    "config_keys", "__version__",
]

Config = _gravcal.Config
BatchResult = _gravcal.BatchResult


# ---------------------------------------------------------------------------
# Configuration.

def _yaml_value(value):
    """A Python value as the YAML text SetConfigValue parses."""
    if isinstance(value, str):
        return value
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float) and not _math.isfinite(value):
        return ".nan" if _math.isnan(value) else (".inf" if value > 0 else "-.inf")
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, (list, tuple, dict)):
        # JSON flow syntax is YAML.
        return _json.dumps(value)
    if isinstance(value, _np.generic):
        return _yaml_value(value.item())
    raise Error("config value %r: expected a string, number, bool, list or dict" % (value,))


def _keys(mapping):
    return [(str(k), _yaml_value(v)) for k, v in mapping.items()]


def _config(config=None, **keys):
    """A :class:`Config` from a YAML path, a dict of keys, or a Config, with
    ``keys`` applied on top in order (the way ``--config f --key v`` works)."""
    if isinstance(config, Config):
        return config.with_keys(_keys(keys)) if keys else config
    if config is None:
        return Config("", _keys(keys))
    if isinstance(config, (str, bytes, _os.PathLike)):
        return Config(_os.fsdecode(config), _keys(keys))
    if isinstance(config, dict):
        merged = dict(config)
        merged.update(keys)
        return Config("", _keys(merged))
    raise Error("config: expected a YAML path, a dict of keys or a gravcal.Config, got %s"
                % type(config).__name__)


config = _config


def config_keys():
    """Every config key with its help text, as ``gravcal help`` lists them."""
    return dict(_gravcal.config_keys())


# ---------------------------------------------------------------------------
# Logs.

def read_log(path, config=None, **keys):
    """Reads a raw log file with the config's reader keys (``format``,
    ``columns``, ``rename``, ``gyro_path``...). Returns a :class:`Log`."""
    return _gravcal.read_log(_os.fspath(path), _config(config, **keys))


def _is_dataframe(x):
    return type(x).__name__ == "DataFrame" and hasattr(x, "columns")


def log(t=None, accel=None, gyro=None, temp=None, *, source="arrays"):
    """A :class:`Log` from arrays: ``t`` (N,) seconds, strictly increasing;
    ``accel`` (N, 3) raw; optional ``gyro`` (N, 3) raw and ``temp`` (N,)
    degrees C. A pandas DataFrame with the contract's column names (t, ax,
    ay, az[, gx, gy, gz][, temp]) may be passed as ``t``. Bad arrays raise
    :class:`Error` naming the array (shape, NaN, time that does not
    increase)."""
    if _is_dataframe(t):
        return _log_from_dataframe(t, source)
    if t is None or accel is None:
        raise Error("a log needs t and accel (or a DataFrame with columns t, ax, ay, az)")
    return _gravcal.make_log(t, accel, gyro, temp, source)


def _log_from_dataframe(frame, source):
    columns = set(frame.columns)
    missing = [c for c in ("t", "ax", "ay", "az") if c not in columns]
    if missing:
        raise Error("DataFrame: column '%s' is missing (the contract's names: t, ax, ay, az, "
                    "gx, gy, gz, temp)" % missing[0])

    def block(names):
        return frame[names].to_numpy(dtype=float)

    gyro = None
    if any(c in columns for c in ("gx", "gy", "gz")):
        absent = [c for c in ("gx", "gy", "gz") if c not in columns]
        if absent:
            raise Error("DataFrame: column '%s' is missing (gyroscope needs gx, gy, gz)"
                        % absent[0])
        gyro = block(["gx", "gy", "gz"])
    temp = frame["temp"].to_numpy(dtype=float) if "temp" in columns else None
    return _gravcal.make_log(frame["t"].to_numpy(dtype=float), block(["ax", "ay", "az"]), gyro,
                             temp, source)


def _as_log(data, cfg, t, accel, gyro, temp):
    """A Log from whatever the caller gave: a Log, a path, a DataFrame, or
    arrays."""
    if data is None:
        return log(t, accel, gyro, temp)
    if any(x is not None for x in (t, accel, gyro, temp)):
        raise Error("give either a log (Log, path or DataFrame) or arrays t/accel, not both")
    if isinstance(data, Log):
        return data
    if isinstance(data, (str, bytes, _os.PathLike)):
        return _gravcal.read_log(_os.fsdecode(data), cfg)
    if _is_dataframe(data):
        return _log_from_dataframe(data, "DataFrame")
    raise Error("log: expected a gravcal.Log, a file path or a pandas DataFrame, got %s"
                % type(data).__name__)


def _log_to_dataframe(self):
    """The log as a pandas DataFrame with the contract's column names."""
    import pandas
    data = {"t": self.t}
    for i, axis in enumerate("xyz"):
        data["a" + axis] = self.accel[:, i]
    if self.gyro is not None:
        for i, axis in enumerate("xyz"):
            data["g" + axis] = self.gyro[:, i]
    if self.temp is not None:
        data["temp"] = self.temp
    return pandas.DataFrame(data)


def _log_repr(self):
    return "<gravcal.Log %r: %d samples%s%s>" % (
        self.source, len(self), ", gyro" if self.gyro is not None else "",
        ", temp" if self.temp is not None else "")


_log_to_csv = Log.to_csv


def _log_to_csv_path(self, path):
    """Writes the log as the contract's CSV (t, ax, ay, az[, gx, gy, gz][, temp]),
    as ``gravcal simulate`` writes raw.csv."""
    _log_to_csv(self, _os.fspath(path))


Log.to_csv = _log_to_csv_path
Log.to_dataframe = _log_to_dataframe
Log.__repr__ = _log_repr


# ---------------------------------------------------------------------------
# Results.

def _convert(value):
    """JSON values for attribute access: dicts become sections, lists of
    numbers (null = NaN) become float arrays, other lists stay lists."""
    if isinstance(value, dict):
        return _Section(value)
    if isinstance(value, list) and value and all(
            isinstance(x, (int, float)) and not isinstance(x, bool) or x is None
            or (isinstance(x, list) and x and all(
                isinstance(y, (int, float)) and not isinstance(y, bool) or y is None for y in x))
            for x in value):
        nan = float("nan")
        return _np.array([[nan if y is None else y for y in x] if isinstance(x, list)
                          else (nan if x is None else x) for x in value], dtype=float)
    return value


class _Section:
    """One object of a result's JSON, read as attributes (``cal.accel.std.bias``)
    or items (``cal["accel"]["std"]``). ``np.asarray`` of a section with a
    ``matrix`` (a covariance) gives the matrix."""

    __slots__ = ("_data",)

    def __init__(self, data):
        self._data = data

    def _dict(self):
        return self._data

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)
        data = self._dict()
        try:
            return _convert(data[name])
        except KeyError:
            raise AttributeError("no key '%s' (keys: %s)" % (name, ", ".join(data))) from None

    def __getitem__(self, name):
        return _convert(self._dict()[name])

    def __contains__(self, name):
        return name in self._dict()

    def __dir__(self):
        return list(self._dict())

    def keys(self):
        return self._dict().keys()

    def to_dict(self):
        """The JSON object as plain dicts and lists (a copy)."""
        return _json.loads(_json.dumps(self._dict()))

    def __array__(self, dtype=None):
        if "matrix" not in self._dict():
            raise TypeError("this section is not a matrix")
        return _np.asarray(_convert(self._dict()["matrix"]), dtype=dtype)

    def __repr__(self):
        return "<gravcal section: %s>" % ", ".join(self._dict())


class Result(dict):
    """A result of noise, discover, plan, check, export or simulate's truth:
    the JSON object the CLI writes, as a dict (so ``==``, ``json.dump`` and
    ``result["key"]`` work as on ``json.load`` of the CLI's file) whose keys
    also read as attributes: ``noise.accel.x.white_noise.value``,
    ``plan.poses``; lists of numbers read as attributes are NumPy arrays
    (null = NaN), as in :class:`Calibration`."""

    __slots__ = ()

    def __getattr__(self, name):
        try:
            value = self[name]
        except KeyError:
            raise AttributeError("no key '%s' (keys: %s)" % (name, ", ".join(self))) from None
        return value if isinstance(value, dict) else _convert(value)

    def __dir__(self):
        return list(self)

    def to_dict(self):
        """Plain dicts and lists (a copy)."""
        return _plain(self)


def _plain(value):
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_plain(v) for v in value]
    return value


def _result(text):
    """JSON text as a :class:`Result` (every object in it one too)."""
    return _json.loads(text, object_hook=Result)


class Calibration(_Section):
    """A calibration result: the calibration JSON of ``gravcal calibrate``.

    Attributes follow the JSON (docs/data_contract.md): ``cal.accel.bias``,
    ``cal.accel.matrix``, ``cal.accel.std.bias``, ``cal.accel.covariance``
    (``.parameters``, ``.matrix``), ``cal.gyro``, ``cal.gravity``,
    ``cal.warnings``... Arrays are NumPy float arrays (null = NaN)."""

    __slots__ = ("_core",)

    def __init__(self, core):
        # The JSON text is parsed on first use.
        _Section.__init__(self, None)
        self._core = core

    def _dict(self):
        if self._data is None:
            self._data = _json.loads(self._core.json)
        return self._data

    @classmethod
    def from_json(cls, path):
        """Reads a calibration JSON file (from ``gravcal calibrate`` or
        :meth:`to_json`)."""
        return cls(_gravcal.Calibration.from_file(_os.fspath(path)))

    @classmethod
    def from_json_text(cls, text, name="calibration"):
        """A calibration from JSON text; ``name`` is used in messages."""
        return cls(_gravcal.Calibration.from_text(text, name))

    def to_json(self, path=None):
        """Writes the calibration JSON file, byte for byte what ``gravcal
        calibrate`` writes (atomically). Without a path, returns the text."""
        if path is None:
            return self._core.json
        self._core.write(_os.fspath(path))
        return None

    @property
    def warnings(self):
        """The method's warnings (the CLI prints them as 'gravcal: warning:')."""
        return list(self._dict().get("warnings", []))

    def apply(self, accel, gyro=None, *, temp=None, t=None):
        """Raw samples to SI with every term of the calibration (the same
        corrector as ``gravcal apply``): ``accel`` (N, 3) -> m/s^2,
        ``gyro`` (N, 3) -> rad/s (its g-sensitivity uses the corrected
        accel). ``temp`` and ``t`` (N) feed the temperature and time terms
        and are required when the calibration has them. Returns
        ``accel_si`` when only accel is given, else ``(accel_si, gyro_si)``.
        Vectorised in C++ without the GIL."""
        a, w = self._core.apply(accel, gyro, temp, t)
        return a if gyro is None else (a, w)

    def brief_report(self):
        """One line: the message and the residual |a| - g before and after, as
        ``gravcal calibrate`` prints it. Only for a result (not one read from
        JSON)."""
        return self._core.report(False)

    def full_report(self):
        """The message, every estimate with its standard deviation, the
        residuals, the solver and the warnings. Only for a result."""
        return self._core.report(True)

    def __str__(self):
        try:
            return self.full_report()
        except Error:
            return repr(self)

    def __repr__(self):
        return "<gravcal.Calibration method=%s, gyro=%s>" % (
            self._dict().get("method"), "gyro" in self._dict())


def _batch_result_repr(self):
    return "<gravcal.BatchResult %s: %s>" % (self.unit, self.status)


BatchResult.__repr__ = _batch_result_repr


# ---------------------------------------------------------------------------
# Commands.

def calibrate(log=None, *, config=None, t=None, accel=None, gyro=None, temp=None,
              attitudes=None, segments=None, noise=None, **keys):
    """Calibrates one session with the config's method (``method`` key).

    ``log`` is a :class:`Log`, a raw log path, or a pandas DataFrame; or
    give arrays ``t``, ``accel`` (and ``gyro``, ``temp``). ``config`` is a
    YAML path, a dict of keys or a :class:`Config`; ``keys`` (e.g.
    ``gravity=9.81744``) apply on top. ``attitudes``, ``segments`` and
    ``noise`` are the side files of the methods that need them. Returns a
    :class:`Calibration`; raises :class:`Error` with the CLI's message."""
    # Exact type checks first: in a loop of calls on logs or paths with a
    # Config, each call stays a handful of cheap tests.
    cfg = config if type(config) is Config and not keys else _config(config, **keys)
    if attitudes is None and segments is None and noise is None:
        side = ("", "", "")
    else:
        side = tuple("" if p is None else _os.fspath(p) for p in (attitudes, segments, noise))
    arrays = t is not None or accel is not None or gyro is not None or temp is not None
    if type(log) is Log and not arrays:
        return Calibration(_gravcal.calibrate(cfg, log, *side))
    if type(log) is str or isinstance(log, (bytes, _os.PathLike)):
        if arrays:
            raise Error("give either a log (Log, path or DataFrame) or arrays t/accel, not both")
        # Read straight into the pipeline, as gravcal calibrate --input does.
        return Calibration(_gravcal.calibrate_file(cfg, _os.fsdecode(log), *side))
    return Calibration(_gravcal.calibrate(cfg, _as_log(log, cfg, t, accel, gyro, temp), *side))


def simulate(config=None, seed=1, *, plan=None, return_files=False, **keys):
    """Simulates a session exactly as ``gravcal simulate --seed`` does.
    Returns ``(truth, log)``: truth.json as a dict and the raw log. ``plan``
    is a plan.json path (``gravcal simulate --plan``): its poses replace
    ``sim_scheme``. With ``return_files=True`` also a dict with the text of
    attitudes.csv and, for ``sim_motion: rate_table``, segments.csv."""
    truth, data, attitudes, segments = _gravcal.simulate(
        _config(config, **keys), int(seed), "" if plan is None else _os.fspath(plan))
    if return_files:
        files = {"attitudes.csv": attitudes}
        if segments:
            files["segments.csv"] = segments
        return _result(truth), data, files
    return _result(truth), data


def _unit_spec(i, unit):
    if isinstance(unit, (str, _os.PathLike)):
        p = _os.fspath(unit)
        return (_os.path.splitext(_os.path.basename(p))[0], p, None, "", [])
    if isinstance(unit, Log):
        return (unit.source if unit.source not in ("", "arrays") else "unit%d" % i, "", unit, "",
                [])
    if isinstance(unit, dict):
        unknown = set(unit) - {"id", "path", "log", "attitudes", "overrides"}
        if unknown:
            raise Error("batch unit %d: unknown field '%s' (id, path, log, attitudes, overrides)"
                        % (i, sorted(unknown)[0]))
        data = unit.get("log")
        if _is_dataframe(data):
            data = _log_from_dataframe(data, str(unit.get("id", "DataFrame")))
        if data is not None and not isinstance(data, Log):
            raise Error("batch unit %d: 'log' must be a gravcal.Log or a DataFrame" % i)
        if (data is None) == (unit.get("path") is None):
            raise Error("batch unit %d: give exactly one of 'path' and 'log'" % i)
        ident = unit.get("id")
        if ident is None:
            ident = _unit_spec(i, unit["path"])[0] if data is None else "unit%d" % i
        return (str(ident), "" if data is not None else _os.fspath(unit["path"]), data,
                _os.fspath(unit.get("attitudes") or ""), _keys(unit.get("overrides") or {}))
    raise Error("batch unit %d: expected a path, a gravcal.Log or a dict, got %s"
                % (i, type(unit).__name__))


class BatchResults(list):
    """The results of :func:`batch` with ``output_dir``, one per unit, and
    the run's text as ``gravcal batch`` prints it."""

    def __init__(self, results, report):
        list.__init__(self, results)
        self._report = report

    def full_report(self):
        """The failed units, the outliers and the run's counts, one line each."""
        return self._report

    def brief_report(self):
        """The run's counts (and why it stopped, if it did)."""
        return "".join(line + "\n" for line in self._report.splitlines()
                       if line.startswith("batch"))

    def __str__(self):
        return self._report


def batch(units, config=None, threads=0, *, pattern="*.csv", output_dir=None, report=None,
          shard=None, **keys):
    """Calibrates many units in parallel (C++ threads, the GIL released), each
    exactly as ``gravcal batch`` would. ``units`` is a list (paths, Logs, or
    dicts with id, path or log, attitudes, overrides), a manifest CSV path, or
    a folder (every file matching ``pattern``). ``threads`` 0 = one per core.
    Returns one :class:`BatchResult` per unit in input order (``unit``,
    ``status``, ``message``, ``content_hash``, ``calibration`` or None,
    ``timings``); a failed unit does not raise.

    With ``output_dir`` the batch writes that folder as ``gravcal batch
    --output-dir`` does (each unit's JSON, its state, summary.csv and
    summary.json; ``report`` the HTML fleet report; ``shard`` "K/N" or
    "auto") and resumes from it: a unit whose stored result is current is
    not computed again (``skipped``; its calibration is read from the
    folder). The list then also has ``full_report()`` / ``brief_report()``."""
    cfg = _config(config, **keys)
    source = _os.fspath(units) if isinstance(units, (str, _os.PathLike)) else None
    folder = source if source is not None and _os.path.isdir(source) else ""
    manifest = source if source is not None and not folder else ""
    if source is None:
        core_units = _gravcal.units([_unit_spec(i, u) for i, u in enumerate(units)])
    elif output_dir is None:
        core_units = (_gravcal.units_from_folder(folder, pattern) if folder
                      else _gravcal.units_from_manifest(manifest, cfg))
    else:
        core_units = []  # The library lists them, leaving its own files out.
    if output_dir is None:
        if report is not None or shard is not None:
            raise Error("batch: report and shard need output_dir")
        results = _gravcal.batch(core_units, cfg, int(threads))
    else:
        out = _os.fspath(output_dir)
        results, text = _gravcal.batch_to_folder(
            core_units, manifest, folder, pattern, cfg, int(threads), out,
            "" if report is None else _os.fspath(report), shard or "")
    for r in results:
        if r.calibration is not None:
            r.calibration = Calibration(r.calibration)
        elif output_dir is not None and r.skipped and r.status == "ok":
            r.calibration = Calibration.from_json(_os.path.join(out, r.unit + ".json"))
    return results if output_dir is None else BatchResults(results, text)


def _check_outputs(outputs, inputs=()):
    """The destination contract (docs/data_contract.md#destinations), before
    any work: ``outputs`` and ``inputs`` as (path or None, name) pairs; an
    input that is not a path (a Log, arrays) is not compared."""
    _gravcal.check_destinations(
        [(_os.fsdecode(p), n) for p, n in outputs if p is not None],
        [(_os.fsdecode(p), n) for p, n in inputs if isinstance(p, (str, bytes, _os.PathLike))])


def noise(log=None, *, config=None, kalibr=None, handheld=None, report=None, t=None, accel=None,
          gyro=None, temp=None, **keys):
    """The noise model of a still log (Allan deviation), as ``gravcal noise``
    writes noise.json: a dict. ``kalibr``, ``handheld`` and ``report`` write
    Kalibr's imu.yaml, the handheld filter's keys and the HTML report there
    (the CLI's --kalibr, --handheld, --report; the same library call)."""
    _check_outputs([(kalibr, "kalibr"), (handheld, "handheld"), (report, "report")],
                   [(log, "log"), (config, "config")])
    cfg = _config(config, **keys)
    paths = ["" if p is None else _os.fspath(p) for p in (kalibr, handheld, report)]
    return _result(_gravcal.noise(cfg, _as_log(log, cfg, t, accel, gyro, temp), *paths))


def discover(log=None, *, config=None, report=None, t=None, accel=None, gyro=None, temp=None,
             **keys):
    """The effects the model misses, as ``gravcal discover`` writes
    discovery.json: a dict. ``report`` writes the HTML report there."""
    _check_outputs([(report, "report")], [(log, "log"), (config, "config")])
    cfg = _config(config, **keys)
    text, html = _gravcal.discover(cfg, _as_log(log, cfg, t, accel, gyro, temp))
    if report is not None:
        _gravcal.write_file(_os.fspath(report), html)
    return _result(text)


# The request of plan and check: the CLI's flag names, and the
# PlanRequest field each sets (workflows/plan.h; defaults are the library's).
_PLAN_FLAGS = {
    "target": "targets", "pose_set": "pose_set", "candidates": "free_candidates",
    "max_time": "max_time_seconds", "overhead": "overhead_seconds",
    "min_hold": "min_hold_seconds", "max_hold": "max_hold_seconds", "max_poses": "max_poses",
    "accel_noise_density": "accel_noise_density",
    "accel_bias_instability": "accel_bias_instability",
    "accel_random_walk": "accel_random_walk", "pose_disturbance": "pose_disturbance",
    "extra_poses": "extra_poses",
}


def _split_request(keys):
    """(PlanRequest, the remaining config keys) from keyword arguments."""
    request = _gravcal.PlanRequest()
    rest = {}
    for key, value in keys.items():
        if key in _PLAN_FLAGS:
            if value is not None:
                setattr(request, _PLAN_FLAGS[key], value)
        else:
            rest[key] = value
    return request, rest


def _noise_source(noise):
    """(path, JSON text) of a noise model given as a noise.json path or a
    dict from :func:`noise`; ("", "") for None."""
    if noise is None:
        return "", ""
    if isinstance(noise, dict):
        return "", _json.dumps(noise)
    if isinstance(noise, (str, bytes, _os.PathLike)):
        return _os.fsdecode(noise), ""
    raise Error("noise: expected a noise.json path or a dict from gravcal.noise, got %s"
                % type(noise).__name__)


def plan(config=None, *, noise=None, output=None, **keys):
    """A recording plan, as ``gravcal plan`` writes plan.json: a dict.

    The request takes the CLI's flag names as keywords: ``target``
    ("accel_bias=0.5mg accel_scale=50ppm"), ``pose_set``, ``candidates``,
    ``max_time``, ``overhead``, ``min_hold``, ``max_hold``, and the
    datasheet noise ``accel_noise_density``, ``accel_bias_instability``,
    ``accel_random_walk``, ``pose_disturbance`` (or ``noise``: a noise.json
    path or the dict :func:`noise` returns); also ``max_poses``. Other
    keywords are config keys. ``output`` writes plan.json there (the CLI's
    file, byte for byte); ``simulate(plan=...)`` reads it."""
    _check_outputs([(output, "output")], [(noise, "noise"), (config, "config")])
    request, rest = _split_request(keys)
    text = _gravcal.plan(_config(config, **rest), request, *_noise_source(noise))
    if output is not None:
        _gravcal.write_file(_os.fspath(output), text)
    return _result(text)


def check(log=None, *, config=None, noise=None, t=None, accel=None, gyro=None, temp=None,
          **keys):
    """What a recorded session determines, as ``gravcal check`` reports it:
    a dict with ``parameters``, ``predicted_std`` (calibration JSON units;
    inf = undetermined), ``undetermined``, ``short_of_target``, ``proposed``
    (extra poses: ``up``, ``hold_s``, ``instruction``), ``message`` and
    ``text`` (what ``gravcal check`` prints). The request keywords are
    :func:`plan`'s (``target``, ``pose_set``, ``accel_noise_density``...);
    ``extra_poses`` sets how many poses are proposed when all is
    determined."""
    request, rest = _split_request(keys)
    cfg = _config(config, **rest)
    return Result(_gravcal.check(cfg, _as_log(log, cfg, t, accel, gyro, temp), request,
                                 *_noise_source(noise)))


def _calibration_of(calibration):
    if isinstance(calibration, (str, bytes, _os.PathLike)):
        calibration = Calibration.from_json(calibration)
    if not isinstance(calibration, Calibration):
        raise Error("calibration: expected a gravcal.Calibration or a calibration JSON path, "
                    "got %s" % type(calibration).__name__)
    return calibration


def thermal_model(calibration):
    """The calibration's thermal model (issue 35) as a dict: ``active``,
    ``reference_temperature``, ``min_temperature``, ``max_temperature``
    (degC), ``lag_time_constant`` (s) and its ``_std``, ``notes``, and per
    sensor (``accel``, ``gyro``) and term (``bias``, ``scale``,
    ``misalignment``): ``order``, ``components``, ``coefficients``
    (components x order, column k-1 the coefficient of (T - T_ref)^k; NaN =
    undetermined by the session) and ``units``."""
    return Result(_gravcal.thermal_model(_calibration_of(calibration)._core))


def thermal_evaluate(calibration, sensor, quantity, temperatures):
    """One thermal term's change from T_ref at ``temperatures`` (degC,
    clamped to the valid range as the correction clamps): ``(values,
    std)``, each of shape (N, components); std NaN where unknown.
    ``sensor`` accel or gyro; ``quantity`` bias (raw units), scale
    (fraction) or misalignment (rad)."""
    return _gravcal.thermal_evaluate(_calibration_of(calibration)._core, str(sensor),
                                     str(quantity), _np.asarray(temperatures, dtype=float))


def export(calibration, to, *, noise=None, name=None, accel_device_id=0, gyro_device_id=0,
           drop_thermal=False):
    """A calibration for another tool, as ``gravcal export --to`` writes
    it: ``to`` is kalibr, openvins, ros, px4, ardupilot or c;
    ``calibration`` a :class:`Calibration` or a calibration JSON path;
    ``noise`` (kalibr, openvins, ros) a noise.json path or the dict of
    :func:`noise`; ``name`` the calibration's name in the file's comment
    (default: its path, as the CLI writes it). Returns a dict: ``files``
    (a list of ``{"name", "text"}``: one file with name "" for a
    single-file target, gravcal_correct.h and .c for c), ``dropped`` (what
    the target cannot hold, one line each), ``full_rms`` and
    ``truncated_rms`` (m/s^2 over the recorded positions) and
    ``message``. With a thermal model, px4 needs ``accel_device_id`` and
    ``gyro_device_id`` (the vehicle's CAL_ACC0_ID, CAL_GYRO0_ID, which
    TC_A0_ID / TC_G0_ID must match); ``drop_thermal`` leaves the thermal
    model out of px4 and ardupilot files."""
    calibration = _calibration_of(calibration)
    result = _gravcal.export(calibration._core, str(to), "" if name is None else str(name),
                             *_noise_source(noise), accel_device_id=int(accel_device_id),
                             gyro_device_id=int(gyro_device_id), drop_thermal=bool(drop_thermal))
    result["files"] = [Result(f) for f in result["files"]]
    return Result(result)


# ---------------------------------------------------------------------------
# Is the calibration still good? (issue 36: compare, verify, the calibration
# store and its history, acceptance limits and the certificate.)

def _calibration(calibration, what="calibration"):
    if isinstance(calibration, (str, bytes, _os.PathLike)):
        calibration = Calibration.from_json(calibration)
    if not isinstance(calibration, Calibration):
        raise Error("%s: expected a gravcal.Calibration or a calibration JSON path, got %s"
                    % (what, type(calibration).__name__))
    return calibration


def compare(a, b, *, level=0.01, space="model", output=None):
    """Are two calibrations of the same unchanged unit? As ``gravcal compare
    a.json b.json``: a :class:`Result` with ``consistent``, ``p_value``,
    ``level``, ``parameters`` (each ``name``, ``difference``, ``std``,
    ``z``), ``changed``, ``undetermined``... (compare.json). ``space`` is
    model or intrinsic (mount-invariant). ``a`` and ``b`` are
    :class:`Calibration` objects or calibration JSON paths."""
    text = _gravcal.compare(_calibration(a, "a")._core, _calibration(b, "b")._core, float(level),
                            str(space))
    if output is not None:
        _gravcal.write_file(_os.fspath(output), text)
    return _result(text)


def verify(calibration, log=None, *, config=None, level=0.01, output=None, t=None, accel=None,
           gyro=None, temp=None, **keys):
    """A short check session (a log, a path or arrays) against a stored
    calibration, as ``gravcal verify``: ``consistent``, or ``changed`` with
    the term, and each parameter's ``minimal_detectable_change``
    (verify.json)."""
    cfg = _config(config, **keys)
    text = _gravcal.verify(_calibration(calibration)._core, cfg,
                           _as_log(log, cfg, t, accel, gyro, temp), float(level))
    if output is not None:
        _gravcal.write_file(_os.fspath(output), text)
    return _result(text)


def history(unit, store, *, level=0.01):
    """The unit's calibrations in a store, as ``gravcal history UNIT --store
    DIR --output``: ``calibrations``, ``parameters`` (values, stds, slope and
    the drift test) and ``steps`` (compare with the one before)."""
    return _result(_gravcal.history(_os.fspath(store), str(unit), float(level)))


def file_calibration(store, unit, calibration, *, date=None):
    """Files a calibration in a store under ``unit`` and ``date`` (ISO 8601
    UTC, default now), as ``calibrate --store``."""
    _gravcal.file_calibration(_os.fspath(store), str(unit), "" if date is None else str(date),
                              _calibration(calibration)._core)


def closest_calibration(store, unit, *, date=None, max_age_days=0.0):
    """The unit's stored calibration closest to ``date`` (default now), as
    ``apply --store --unit --at`` picks it: a :class:`Calibration` with
    ``.store_entry`` (``date``, ``file``, ``warning``: non-empty when older
    than ``max_age_days``)."""
    entry = _gravcal.closest_calibration(_os.fspath(store), str(unit),
                                         "" if date is None else str(date), float(max_age_days))
    if entry["warning"]:
        _warnings.warn(entry["warning"])
    return Calibration.from_json(entry["file"]), Result(entry)


def _limits_source(limits):
    """(path, YAML text) of limits given as a path or a dict."""
    if isinstance(limits, dict):
        return "", _json.dumps(limits)  # JSON is YAML
    return _os.fspath(limits), ""


def check_limits(calibration, limits):
    """The calibration against acceptance limits (a limits YAML path, or a
    dict of the same keys: ``parameters``, ``residual_rms``,
    ``accel_noise_density``, ``gyro_noise_density``, ``temperature``...): a
    :class:`Result` with ``verdict`` (pass or fail), ``message`` and
    ``limits`` (each ``name``, ``measured``, ``min``, ``max``, ``pass``,
    ``checked``, ``why``)."""
    return _result(_gravcal.check_limits(_calibration(calibration)._core,
                                         *_limits_source(limits)))


def certificate(calibration, *, limits=None, unit="", station=None, date=None, input_file="",
                config_file="", coverage_factor=2.0, output=None):
    """The calibration certificate, as ``calibrate --certificate PREFIX``
    writes it: returns ``(certificate, html)``, the certificate JSON as a
    :class:`Result` and the self-contained HTML page. With ``output`` (a
    path prefix) writes ``<output>.json`` and ``<output>.html``. The
    station defaults to the host name; ``config_file`` is recorded with its
    text."""
    import socket
    config_text = ""
    if config_file:
        with open(config_file, encoding="utf-8") as f:
            config_text = f.read()
    path, text = ("", "") if limits is None else _limits_source(limits)
    json_text, html = _gravcal.certificate(
        _calibration(calibration)._core, limits is not None, path, text, str(unit),
        socket.gethostname() if station is None else str(station), "" if date is None else date,
        _os.fspath(input_file), _os.fspath(config_file) if config_file else "(defaults)",
        config_text, float(coverage_factor))
    if output is not None:
        _gravcal.write_file(_os.fspath(output) + ".json", json_text)
        _gravcal.write_file(_os.fspath(output) + ".html", html)
    return _result(json_text), html


__all__ += ["compare", "verify", "history", "file_calibration", "closest_calibration",
            "check_limits", "certificate"]
class Recorder:
    """Guided live calibration from your own acquisition loop, as ``gravcal
    record`` does it (docs/workflows/record.md).

    ``Recorder(config, targets)``: ``config`` a config path, dict or
    :class:`Config`; ``targets`` as ``gravcal plan --target``
    ("accel_bias=0.3mg accel_scale=100ppm"). ``feed(t, accel, gyro=None)``
    takes one sample (raw units, t in seconds) and returns the events it
    caused, as dicts (docs/data_contract.md, "Record events"): most samples
    cause none; a ``suggest`` event says where to put the unit next.
    ``done`` turns true when the targets are met (or at ``max_time``
    seconds of stream time). ``finish(reason)`` calibrates what was fed
    (exactly ``calibrate`` on :attr:`log_csv`) and returns the
    :class:`Calibration` (raises :class:`Error` with the reason when it
    fails); :attr:`done_event` is then the ``done`` event either way."""

    def __init__(self, config=None, targets="", *, pose_set="faces+45", max_time=0.0,
                 accel_noise_density=0.0, noise=None, **keys):
        self._core = _gravcal.Recorder(_config(config, **keys), str(targets), str(pose_set),
                                       float(max_time), float(accel_noise_density),
                                       *_noise_source(noise))
        self.done_event = None

    def feed(self, t, accel, gyro=None, temp=None):
        """One sample; returns the list of events (dicts) it caused."""
        accel = _np.asarray(accel, dtype=float).reshape(3)
        if gyro is not None:
            gyro = _np.asarray(gyro, dtype=float).reshape(3)
        events = self._core.feed(float(t), accel, gyro, _math.nan if temp is None else float(temp))
        return [_json.loads(e) for e in events]

    @property
    def done(self):
        """True once the session is over (targets met or max_time)."""
        return self._core.done

    @property
    def log_csv(self):
        """The recorded log as contract CSV text (after :meth:`finish`)."""
        return self._core.log_csv

    def finish(self, reason=None):
        """Ends the session and returns the :class:`Calibration` of what was
        fed; ``reason`` defaults to the recorder's own ("targets_met") or
        "end_of_input"."""
        if reason is None:
            reason = self._core.done_reason or "end_of_input"
        calibration, done, message = self._core.finish(str(reason))
        self.done_event = _json.loads(done)
        if calibration is None:
            raise Error(message)
        return Calibration(calibration)
