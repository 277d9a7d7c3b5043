"""Results as objects: what one run produced, in SI, readable back from its archive.

A :class:`Result` is plain data with units, laid out as in the archive (``docs/archive.md``):

* ``data``: named arrays keyed by their archive path (``"results/per_rotation/I_dec"``,
  ``"results/impacts/time_s"``, ``"results/theta_deg"`` ...), each a :class:`NamedArray` with its unit;
* ``groups``: named attribute groups (``"results/summary"``, ``"results/pass"`` ...), each a
  :class:`AttrGroup` of values and their units (read-only mappings, as the arrays are read-only views);
* ``series``: time series (:class:`Series`, H5MD ``{step, time, value}``);
* ``provenance``: how the run was made (solver, time step and how it was chosen, run facts);
* ``scenario``: the resolved :class:`bearingsim.scenario.Scenario` it was run from.

A model builds its result from what it computed and never sees an archive; :mod:`bearingsim.archive`
writes any result and reads it back into the same class, so every figure (``plot_*`` methods, each
returning a matplotlib figure without showing it) can be drawn again from a file.
"""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from bearingsim.datatypes import AttrGroup, NamedArray, ReadOnlyMapping, Series
from bearingsim.errors import UserError, check_path

PER_ROTATION = "results/per_rotation"
IMPACTS = "results/impacts"
SUMMARY = "results/summary"
SET_NOTE_CHARS = 60  # longest list of --set values a title gives (more: their count)


def set_note(command) -> str:
    """`` (--set operating.inner_ring_speed_rpm=500)``: the ``--set`` values of the command line that made a
    run (its provenance's ``command``), to go beside the scenario's name in a title, since the file of that
    name does not hold them; `` (with 3 --set values)`` when they are long; "" when none (or no command)."""
    import shlex

    try:
        words = shlex.split(command) if isinstance(command, str) else []
    except ValueError:  # not a shell line
        return ""
    sets = [w.removeprefix("--set=") if w.startswith("--set=") else nxt
            for w, nxt in zip(words, words[1:] + [""]) if w.startswith("--set=") or w == "--set" and nxt]
    if not sets:
        return ""
    text = ", ".join(sets)
    return f" (--set {text})" if len(text) <= SET_NOTE_CHARS else f" (with {len(sets)} --set values)"


def read_only(a) -> np.ndarray:
    """A read-only view of the array ``a`` (what a result hands out: writing into it raises numpy's "assignment
    destination is read-only", so the result, its summary and the archive it saves stay as the run made them)."""
    view = np.asarray(a).view()
    view.setflags(write=False)
    return view


def _read_only_data(data: dict[str, NamedArray]) -> dict[str, NamedArray]:
    """``data`` with each array a read-only view (:func:`read_only`)."""
    return {k: replace(v, data=read_only(v.data)) if isinstance(v.data, np.ndarray) else v for k, v in data.items()}


def _mapping_of(name: str, value, kind: type | None = None, what: str = "values"):
    """``value``, assigned to the result's attribute ``name``, when it is a mapping of names to ``what`` (each a
    ``kind`` where given); else a one-line :class:`bearingsim.errors.UserError` naming the attribute (it was an
    AttributeError of ``.items`` or ``.attrs`` deep in the setter)."""
    from collections.abc import Mapping

    if not isinstance(value, Mapping):
        raise UserError(f"Result.{name}: expected a mapping of names to {what}, such as a dict (got "
                        f"{type(value).__name__})")
    bad = next((k for k, v in value.items() if kind is not None and not isinstance(v, kind)), None)
    if bad is not None:
        raise UserError(f"Result.{name}[{bad!r}]: expected a bearingsim.datatypes.{kind.__name__} (got "
                        f"{type(value[bad]).__name__})")
    return value


def _read_only_values(values) -> ReadOnlyMapping:
    """A read-only copy of the named values ``values`` (:class:`bearingsim.datatypes.ReadOnlyMapping`), a value
    that is an array a read-only view (:func:`read_only`)."""
    return ReadOnlyMapping({k: read_only(v) if isinstance(v, np.ndarray) else v for k, v in values.items()})


def _read_only_groups(groups: dict[str, AttrGroup]) -> dict[str, AttrGroup]:
    """``groups`` with each group's values and units read-only copies (:func:`_read_only_values`)."""
    return {k: replace(g, attrs=_read_only_values(g.attrs), units=ReadOnlyMapping(g.units)) for k, g in groups.items()}


class Result:
    """One run's results (base class; :class:`bearingsim.reduced.ReducedResult` and
    :class:`bearingsim.multibody.MultibodyResult` add the model's figures).

    Parameters
    ----------
    scenario : the resolved scenario that was run.
    data, groups, series, provenance : see the module docstring.
    tables : archive paths of the groups in ``data`` that are tables (equal-length columns), with
        their descriptions, e.g. ``{"results/impacts": "roller-cage impacts ..."}``.
    """

    model = "?"

    #: what an archive of this model holds, checked on read (:func:`bearingsim.archive.check_layout`):
    #: archive path -> its dimensions, each a length or a name; arrays sharing a name share its length,
    #: and :meth:`archive_dims` fixes some names from the scenario; in the order the model lays its arrays
    #: out, which a result read back keeps (a table's columns: the order its ``@columns`` stores)
    LAYOUT: dict[str, tuple] = {}
    #: sets of arrays of :attr:`LAYOUT` that are optional: all of a set or none
    OPTIONAL: tuple[frozenset, ...] = ()
    #: arrays of :attr:`LAYOUT` that hold text (the others hold numbers)
    TEXT_ARRAYS: frozenset = frozenset()
    #: the archive paths of the arrays the figures draw (``bearingsim plot`` reads only these)
    FIGURE_DATA: tuple[str, ...] = ()
    #: the keys of ``/results/summary`` that must be numbers (the figures and the CLI print them)
    SUMMARY_NUMBERS: tuple[str, ...] = ()
    #: keys of ``/results/summary`` that are numbers where present (added after archives were written without)
    SUMMARY_OPTIONAL: tuple[str, ...] = ()
    #: arrays a later version records beside the same numbers (no model version bump): absent from the archives
    #: written before, which is no difference of the run (:func:`bearingsim.compare.compare_results`)
    ADDED_ARRAYS: frozenset = frozenset()

    #: read from an archive with only part of its arrays (``simulation.load(path, only=...)``): ``(path, only,
    #: the archive paths of the arrays not read)``, set by :func:`bearingsim.archive.read`; None: it holds them all
    partial: tuple | None = None

    @classmethod
    def archive_dims(cls, scenario) -> dict[str, int]:
        """The lengths of named dimensions of :attr:`LAYOUT` that ``scenario`` fixes."""
        return {"rotations": scenario.numerics.rotations}

    def __init__(self, scenario, data: dict[str, NamedArray], groups: dict[str, AttrGroup],
                 series: dict[str, Series] | None = None, provenance: dict[str, Any] | None = None,
                 tables: dict[str, str] | None = None):
        self.scenario = scenario
        # what the result holds is as the run made it: its arrays read-only views (read_only), the run's own
        # arrays untouched (an in-place change of r.data[...].data or r.series[...].value would have changed the
        # result, its summary's meaning and the archive it saves)
        self.data = _read_only_data(data)
        self.groups = groups  # their values and units read-only too (the summary is read from them)
        self.series = series or {}
        self.provenance = provenance or {}  # read-only too: the record of how the run was made
        self.tables = dict(tables or {})
        self.notes: list[str] = []  # one-line notes of a run that is plausible but not clean (simulation.run)
        self._parameters = None

    def __setstate__(self, state: dict) -> None:
        """Unpickled (what ``ProcessPoolExecutor().map(bearingsim.run, ...)`` hands back): pickle rebuilds the
        arrays as writable copies, so they are made read-only again (those of the groups' values too), as those of
        the run that was pickled."""
        self.__dict__.update(state)
        self.data = _read_only_data(self.data)
        self.series = self.__dict__.get("_series", {})
        self.groups = self.__dict__.get("_groups", {})
        self.provenance = self.__dict__.get("_provenance", {})

    @property
    def groups(self) -> dict[str, AttrGroup]:
        """The named attribute groups, by archive path; each group's ``attrs`` and ``units`` are read-only
        (:class:`bearingsim.datatypes.ReadOnlyMapping`: ``attrs[k] = v`` raises a TypeError), as the arrays of
        :attr:`data` are: :attr:`summary` and the archive :meth:`save` writes are read from them."""
        return self._groups

    @groups.setter
    def groups(self, groups: dict[str, AttrGroup]) -> None:
        self._groups = _read_only_groups(_mapping_of("groups", groups, AttrGroup, "attribute groups"))

    @property
    def provenance(self) -> ReadOnlyMapping:
        """How the run was made (solver, time step and how it was chosen, the code and machine that ran it), by
        name; read-only (:class:`bearingsim.datatypes.ReadOnlyMapping`), as the rest of the result: it is the
        record of the run, which :meth:`save` stores."""
        return self._provenance

    @provenance.setter
    def provenance(self, provenance) -> None:
        self._provenance = _read_only_values(_mapping_of("provenance", provenance))

    @property
    def series(self) -> dict[str, Series]:
        """The time series the run recorded, by name (their arrays read-only, as :attr:`data`'s)."""
        return self._series

    @series.setter
    def series(self, series: dict[str, Series]) -> None:
        series = _mapping_of("series", series, Series, "time series")
        self._series = {k: replace(s, step=read_only(s.step), time=read_only(s.time), value=read_only(s.value))
                        for k, s in series.items()}

    # --- the API ---------------------------------------------------------------------------
    @property
    def parameters(self):
        """The SI :class:`bearingsim.parameters.Parameters` of :attr:`scenario`."""
        if self._parameters is None:
            self._parameters = self.scenario.parameters
        return self._parameters

    @property
    def summary(self) -> dict[str, float]:
        """The headline numbers in SI (names carry their unit), as floats, by name (the order the archive
        stores them in: a result read back lists them as the run's result did). A text value of the summary
        (a multibody run's ``scene``) is not among them: ``groups["results/summary"].attrs["scene"]``."""
        attrs = self.groups[SUMMARY].attrs
        return {k: float(v) for k, v in sorted(attrs.items())
                if isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, bool)}

    @property
    def summary_units(self) -> dict[str, str]:
        """The unit of each summary value, by name."""
        return dict(sorted(self.groups[SUMMARY].units.items()))

    @property
    def per_rotation(self) -> dict[str, np.ndarray]:
        """Per cage rotation arrays: ``[rotations, pockets]`` for the pockets' (``I_dec``, ``I_acc``, ...),
        ``[rotations]`` for the cage's own (a multibody run's ``cage_rest_offset``, ``cage_rest_angle``);
        ``docs/archive.md`` lists them."""
        return self._under(PER_ROTATION)

    @property
    def impacts(self) -> dict[str, np.ndarray]:
        """The impact table: one array per column (``time_s``, ``theta_deg``, ``face`` ...)."""
        return self._under(IMPACTS)

    @property
    def impacts_end_s(self) -> float | None:
        """The time [s] of the impact table's last row when the table filled its rows (provenance
        ``impacts_table_full``; ``multibody.core.IMPACT_CAPACITY``): it lists the impacts up to there only. None
        when it holds every impact."""
        if not self.provenance.get("impacts_table_full", False):  # first: most results need not read the table
            return None
        times = self.impacts.get("time_s", ())
        return float(times[-1]) if len(times) else None

    def get(self, name: str) -> np.ndarray:
        """The array stored at ``results/<name>`` (e.g. ``"theta_deg"``, ``"wear/paper_index_rear"``). A name
        this result holds no array under is a one-line :class:`bearingsim.UserError` naming the names it has."""
        arr = self.data.get(f"results/{name}") if isinstance(name, str) else None
        if arr is None:
            if isinstance(name, str):
                self.require(f"results/{name}", f"get({name!r})")
            raise UserError(self._unknown_array(name))
        return read_only(arr.data)

    def require(self, prefix: str, what: str) -> None:
        """Refuse ``what`` in one line (:class:`bearingsim.UserError`) when this result was read from its archive
        without an array at or under the archive path ``prefix`` (``""``: any), naming it and how to read them all."""
        _require(self.partial, prefix, what)

    def _unknown_array(self, name) -> str:
        """The message of :meth:`get` for ``name``: the closest names (if any) and every name there is, those
        of a group together (``per_rotation/{I_dec, I_acc}``)."""
        import difflib

        if not isinstance(name, str):
            return f"get({name!r}): expected the name of an array under results/ (a str), got {type(name).__name__}"
        names = [k.removeprefix("results/") for k in self.data if k.startswith("results/")]
        folders: dict[str, list[str]] = {}
        for n in names:
            folder, _, leaf = n.rpartition("/")
            folders.setdefault(folder, []).append(leaf)
        listed = [", ".join(leaves) if not folder else f"{folder}/{{{', '.join(leaves)}}}"
                  for folder, leaves in folders.items()]
        close = difflib.get_close_matches(name, names, n=3)
        hint = f" (did you mean {' or '.join(close)}?)" if close else ""
        return f"get({name!r}): no array results/{name} in this {self.model} result{hint}; its arrays: " + (
            ", ".join(listed) or "none")

    def _under(self, prefix: str) -> dict[str, np.ndarray]:
        p = prefix + "/"
        arrays = {k[len(p):]: read_only(v.data) for k, v in self.data.items()
                  if k.startswith(p) and "/" not in k[len(p):]}
        return arrays if self.partial is None else _Arrays(arrays, partial=self.partial, prefix=prefix)

    def to_dataframe(self, what: str = "per_rotation", units_in_names: bool = False):
        """A pandas DataFrame of ``what`` (needs the extra ``bearingsim[frames]``):

        * ``"per_rotation"``: one row per (rotation, pocket) (a MultiIndex), one column per
          per-rotation array (``I_dec``, ``I_acc``, ...; a number per rotation, such as where the cage
          rests, in each of its pockets' rows);
        * ``"impacts"``: one row per roller-cage impact (``time_s``, ``theta_deg``, ``face`` ...);
        * ``"observables"``: the time series, indexed by ``time_s`` (vectors split into ``_x``, ``_y``);
        * ``"summary"``: one row of the summary numbers.

        Units (SI) in ``df.attrs["units"]``; ``units_in_names=True`` also puts them in the column names
        (``"I_dec [N s]"``). :mod:`bearingsim.frames`."""
        from bearingsim.frames import result_dataframe

        return result_dataframe(self, what, units_in_names)

    def to_xarray(self):
        """An xarray Dataset (needs the extra ``bearingsim[frames]``): per-rotation arrays on
        ``(rotation, pocket)``, the impacts as ``impact_<column>`` on ``impact``, the time series on
        ``time``; each variable's unit in its ``attrs["units"]``, the summary numbers (and their
        ``units_<key>``), the scenario's name, model and TOML in the Dataset's attrs."""
        from bearingsim.frames import result_xarray

        return result_xarray(self)

    def animate(self, out, **kw) -> Path:
        """Write an animation of this run's stored motion (``.mp4`` or ``.gif``) to ``out``; return the path.
        ``kw``: ``rotations=(a, b)``, ``exaggerate``, ``fps``, ``progress`` of
        :func:`bearingsim.simulation.animate` (docs/animation.md). A multibody run stores the motion of
        the window its ``[output] motion_*`` keys set."""
        from bearingsim.animation import render_result

        return render_result(self, out, **kw)

    def save(self, path, force: bool = False) -> Path:
        """Write this result as an archive at ``path`` (``.h5`` or ``.hdf5``; atomically: a temporary file
        renamed when complete) and return the path. Missing folders are created; a bearingsim archive at
        ``path`` of the same scenario is replaced, one of a different scenario only with ``force=True`` (as
        ``bearingsim run -o`` replaces it only with ``--force``); any other file there, and a symbolic link
        (even to an archive: a link is the user's, as at a figure path), is refused (:class:`bearingsim.UserError`,
        nothing written); so is a value of :attr:`provenance` or :attr:`groups` the archive cannot store (one
        made with the result or assigned to it: :func:`bearingsim.archive.check_storable` names it and its type)."""
        from bearingsim import archive

        check_path(path, "path", "the archive (.h5)")
        self.require("", "save()")  # an archive without them would be a damaged one
        archive.check_storable(self, "save()")  # h5py would refuse it mid-write with its own TypeError
        if not isinstance(force, bool):
            raise UserError(f"save(): force: expected True or False (got {type(force).__name__})")
        if not force and not Path(path).is_symlink():  # a link is refused as it is, whatever it leads to
            archive.check_same_scenario(Path(path), self.scenario,
                                        "give another path, or save(..., force=True) to replace it")
        return archive.write(self, path)

    # --- figures ---------------------------------------------------------------------------
    #: names of the figures of this model: method ``plot_<name>`` draws each, file ``<stem>_<name>.png``
    FIGURES: tuple[str, ...] = ()

    def figures(self) -> dict:
        """Every figure of this result, ``{name: matplotlib figure}`` (none is shown)."""
        return {name: getattr(self, f"plot_{name}")() for name in self.FIGURES}

    def save_figures(self, stem) -> list[Path]:
        """Write every figure as ``<stem>_<name>.png``; return the paths. Missing folders are created, as
        :meth:`save` does. Every path is checked before any figure is drawn: a folder that cannot be made
        or written in, or a path that holds anything but a figure bearingsim drew (a link, a folder, a user's
        picture), is refused with a one-line :class:`bearingsim.UserError` and nothing is written
        (:func:`bearingsim.outputs.check_replaceable`)."""
        from bearingsim.archive import check_writable_dir
        from bearingsim.outputs import check_folder_path, check_replaceable, figure_path, is_own_png
        from bearingsim.plotting import save_figure

        stem = check_path(stem, "stem", "the figures' stem (<stem>_<name>.png)")
        paths = {name: figure_path(stem, name) for name in self.FIGURES}
        folder = check_folder_path(Path(stem).parent)  # a file in the way: refused, nothing created
        for path in paths.values():
            check_replaceable(path, is_own_png, "figure")
        check_writable_dir(folder)
        return [save_figure(getattr(self, f"plot_{name}")(), path) for name, path in paths.items()]

    #: at most this many differences from the preset are named in a title (then "+N more")
    TITLE_DIFFERENCES = 6

    def title(self) -> str:
        """``<scenario>: <what ran>, <speed> rpm <direction>, <load> N``: names the run as it was actually
        made, the command line's ``--set`` values beside the scenario's name (:func:`set_note`); a second line
        names what the scenario sets differently from its preset and the defaults
        (:func:`bearingsim.scenario.differences_from_preset`), so that two runs' figures differ."""
        from bearingsim.scenario import differences_from_preset

        sc = self.scenario
        op = sc.operating
        head = (f"{sc.name}{set_note(self.provenance.get('command'))}: {self.description()}, "
                f"{op.inner_ring_speed_rpm:g} rpm {op.direction}, {op.radial_load_N:g} N")
        diffs = differences_from_preset(sc)
        if not diffs:
            return head
        n = self.TITLE_DIFFERENCES
        more = f", +{len(diffs) - n} more" if len(diffs) > n else ""
        return f"{head}\n{', '.join(diffs[:n])}{more}"

    def description(self) -> str:  # pragma: no cover - overridden
        return self.model

    def __repr__(self) -> str:
        s = self.summary
        head = ", ".join(f"{k}={s[k]:.4g}" for k in ("I_dec_mean_Ns", "I_acc_mean_Ns") if k in s)
        given = getattr(self.scenario, "overrides_text", str)()  # its scenario's overrides ("" without any)
        return f"<{type(self).__name__} {self.scenario.name!r}{given}: {head}>"


def _require(partial: tuple | None, prefix: str, what: str) -> None:
    """:meth:`Result.require` of a result whose :attr:`Result.partial` is ``partial``."""
    if partial is None:
        return
    path, only, unread = partial
    missing = [u for u in unread if not prefix or u == prefix or u.startswith(prefix + "/")]
    if missing:
        more = f" and {len(missing) - 1} more" if len(missing) > 1 else ""
        raise UserError(f"{what}: this result was read from {path} without {missing[0]}{more} (only={only!r}); "
                        f"bearingsim.load({str(path)!r}) reads every array")


class _Arrays(dict):
    """The arrays under an archive path (``per_rotation``, ``impacts``) of a result read with part of them: a name
    its archive holds but was not read (``simulation.load(path, only=...)``) is a one-line
    :class:`bearingsim.UserError`, not a KeyError."""

    def __init__(self, arrays: dict, *, partial: tuple, prefix: str):
        super().__init__(arrays)
        self.partial, self.prefix = partial, prefix

    def __missing__(self, key):
        if isinstance(key, str):
            _require(self.partial, f"{self.prefix}/{key}", f"{self.prefix.removeprefix('results/')}[{key!r}]")
        raise KeyError(key)


class MemorySink:
    """The default sink of a run: time series kept in memory and handed to the result.

    A sink is what a model streams its time series into (``timeseries(name, value_shape, unit,
    description)`` returns an appender with ``append(step, time, value)``; ``discard_timeseries()``
    drops them for a restarted run; ``collect()`` gives what the result holds).
    :class:`bearingsim.archive.Spool` is the other one: it streams into the archive's file.
    """

    def __init__(self):
        self._series: dict[str, _MemorySeries] = {}

    def timeseries(self, name: str, value_shape=(), unit: str = "1", description: str = ""):
        s = _MemorySeries(tuple(value_shape), unit, description)
        self._series[name] = s
        return s

    def discard_timeseries(self) -> None:
        self._series.clear()

    def collect(self) -> dict[str, Series]:
        return {name: s.series() for name, s in self._series.items()}


class _MemorySeries:
    def __init__(self, shape, unit, description):
        self.shape, self.unit, self.description = shape, unit, description
        self.steps, self.times, self.values = [], [], []

    def append(self, step, time_s, value) -> None:
        step = np.atleast_1d(np.asarray(step, dtype=np.int64))
        self.steps.append(step)
        self.times.append(np.atleast_1d(np.asarray(time_s, dtype=np.float64)))
        self.values.append(np.asarray(value, dtype=np.float64).reshape((len(step), *self.shape)))

    def series(self) -> Series:
        if not self.steps:
            return Series(np.zeros(0, np.int64), np.zeros(0), np.zeros((0, *self.shape)), self.unit, self.description)
        return Series(np.concatenate(self.steps), np.concatenate(self.times), np.concatenate(self.values),
                      self.unit, self.description)
