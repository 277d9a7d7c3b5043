"""The version of each model's numbers: which archives a sweep's resume may reuse.

``MODEL_VERSIONS[model]`` is an integer, **bumped when a change moves numbers**: in the same commit
as any change after which some scenario run with that model gives a different summary number or
per-rotation array (in any bit), whether the change is in the model's physics, a kernel, a solver,
the time-step choice, or code the model shares with the other one (``laws.py``, ``parameters.py``:
then both are bumped). A change that leaves every number bit-identical (a refactoring, a speed-up,
docs, messages) keeps it. Inputs need no version: a different preset, default or override changes
the resolved scenario, and a sweep matches archives by their scenario text first.

Each model stamps its result's provenance with ``model_version`` (:mod:`bearingsim.reduced`,
:mod:`bearingsim.multibody`); a sweep counts a case's archive ``cached`` only when its scenario is
the case's and its ``model_version`` is the current one, ``stale`` (run again) otherwise, an archive
without one (written before models had a version) included (:func:`bearingsim.sweeps.index.read_cached`).

Why a number bumped by hand and not a digest of the model's sources: a digest would change with
every edit of any file the model imports, so the refactorings this project checks to be
bit-identical would throw every stored archive away, and which files count (numba kernels, shared
laws, the pymunk glue) would be a guess that is wrong in one direction or the other. A number says
what the code's authors know: whether the numbers moved (the golden and bit-identity tests show
it). What it does not follow: other versions of numpy, numba or pymunk, which may move the last
bits; each archive's provenance records them (``version_<package>``, shown by ``bearingsim rerun``).

This module imports nothing, so a sweep's resume check does not load the models.
"""

# multibody 2: exact arc pocket faces over the cage wall; 3: the rigid scene's automatic step at 80 % of the
# overlap bound; 4: a worn face's contact at the nearest point of its material (its edges); 5: the automatic
# step's impact speed across the play worn faces leave (core.worn_play); 6: where the cage rests, in the
# summary (cage_rest_offset_m, cage_rest_angle_deg) and per rotation (numbers an archive of 5 lacks; no
# number of 5 moved); 7: the paper's wear index (/results/wear/paper_index_*) from the normal impulse, not its
# circumferential component; 8: the kinematic_cage scene's automatic step divided by 8 (core.KINEMATIC_DT_DIVISOR:
# its I_dec moves, +6.7 % at 3000 rpm; no other scene's number moved); 9: the quasi-static ring's solve converges
# where Newton cycled (forces.solve_ring_centre: Armijo-damped Newton, then nested bracketing; every Hertz-raceway
# run moves, rigid raceways bit-identical); 10: the cage slip and the load zone's half angle per rotation
# (/results/per_rotation/cage_slip, load_zone_half_angle: their standard errors' series, which an archive of 9
# lacks; no number of 9 moved)
#: version of each model's numbers (bumped when a change moves numbers; see the module docstring)
MODEL_VERSIONS = {"reduced": 1, "multibody": 10}

#: the models, by the name a scenario's ``model`` key and an archive's ``/bearingsim@model`` give
MODELS = tuple(MODEL_VERSIONS)

#: the figures each model's result draws (its ``FIGURES``), written beside an archive as ``<stem>_<name>.png``;
#: a run removes those of an earlier run at its stem that it does not write itself (bearingsim.simulation)
MODEL_FIGURES = {"reduced": ("pass",), "multibody": ("forces", "impulses", "orbit", "wear")}
