"""Named records that the kernels take instead of long positional argument lists.

Plain :func:`collections.namedtuple` types: Numba passes them into jitted code as tuples
with named fields, so a kernel reads ``silicone.mu`` or ``nodes.phi_trig``. Every array field is
float64 unless said otherwise; SI units.
"""

from __future__ import annotations

from collections import namedtuple

from ..physics.records import Nodes, Ogden, Section

__all__ = ["AngleTables", "CoilTable", "Control", "Estimator", "GridAxes", "GridOut",
           "LoopControl", "LoopMuscle", "LoopPlant", "LoopReference", "Muscle", "Muscles",
           "Nodes", "Ogden", "Options", "PointDesigns", "PointOut", "Section",
           "SimOut", "Supply", "TableSpec"]

# Ogden (``mu`` [Pa], ``alpha`` [-], one entry per term; the pointwise kernel takes 2-D
# arrays (sample, term) with one row or one row a design), Nodes (the quadrature of the
# material moment) and Section (``radius``, ``wall``, ``base`` [m]) are the physics layer's
# records (:mod:`nylonflex.physics.records`), which the formulas take too.

#: The axes of a slab of the design grid: ``radius`` (the slab's radii), ``wall``,
#: ``length``, ``wrap`` [m, m, m, rad]; ``base_thickness`` [m] (<= 0: b = t); the curve axes
#: ``stroke`` [-] and ``pressure`` [Pa]; ``p_atm`` the initial chamber pressure [Pa].
GridAxes = namedtuple("GridAxes", "radius wall length wrap base_thickness stroke pressure p_atm")

#: Per coil index: ``s_max`` [-], ``force_limit`` F_lim [N], ``width`` of the coiled muscle
#: [m], ``r_per_len`` r'(C) [ohm/m] and ``loss_per_len`` lambda'(C) [W/(K m)] (docs/model.md
#: s. 9). The grid kernel takes one entry a coil index of the axis, the pointwise kernel one
#: a design.
CoilTable = namedtuple("CoilTable", "s_max force_limit width r_per_len loss_per_len")

#: Output arrays of the grid kernel: ``design`` (float design variables, the rows of
#: :mod:`.rows`, then the slab's design shape), ``flags`` (int8, rows ``limit`` and
#: ``validity``: one array, since Numba's parallel loops lost the writes to a second int8
#: output of the same record), ``nylon_force``,
#: ``bend_angle``, ``tip_force`` (the registry's dims).
GridOut = namedtuple("GridOut", "design flags nylon_force bend_angle tip_force")

#: The grid kernel's working arrays, one set a call (a thread's chunk), reused for every
#: (radius, wall) pair of it (:func:`~.design.grid_scratch`): the section's node table
#: ``y`` [m], ``wy`` [m^3], ``wyy`` [m^4] and ``work`` (MOMENT_WORK_ROWS, nodes); the
#: bend-angle curve's ``kappa`` [1/m], ``rate`` [1/(m Pa)] and ``rate2`` [1/(m Pa^2)] a
#: pressure; p(s) ``stroke_pressure`` [Pa] and S_theta(s) ``stroke_hoop`` [Pa] a stroke.
#: Made by the caller, so that the compiled kernel allocates nothing (NumPy's allocation
#: was 0.15 s of its first compile).
GridScratch = namedtuple("GridScratch", "y wy wyy work kappa rate rate2 stroke_pressure "
                                        "stroke_hoop")

#: The muscle's thermal and eq. (1)-(2) constants, float64 arrays of one entry (the grid
#: kernel) or one a design (the pointwise kernel): ``t_amb``, ``t_max``, ``t_g`` [K],
#: ``gamma`` [1/K], ``beta`` [-], ``sigma_g`` [K], ``r_per_len`` r' [ohm/m], ``c_per_len``
#: c' [J/(K m)], ``loss_per_len`` lambda' [W/(K m)], ``force_coeff`` c of eq. (1) [N/K].
#: The design kernels read r' and lambda' per coil index from :data:`CoilTable` instead.
Muscle = namedtuple("Muscle", "t_amb t_max gamma beta t_g sigma_g r_per_len c_per_len "
                              "loss_per_len force_coeff")

#: Run options: ``model`` (int code of ``physics.limits.MODELS``), ``voltage`` the supply
#: [V] (<= 0: none), ``stretch_max`` the top of the silicone's fitted stretch range [-].
Options = namedtuple("Options", "model voltage stretch_max")

#: Scattered designs, one entry each: ``radius``, ``wall``, ``base``, ``length`` [m],
#: ``wrap`` [rad].
PointDesigns = namedtuple("PointDesigns", "radius wall base length wrap")

#: Output of the pointwise kernel: ``design`` (float variables, shape (N_FLOAT_DESIGN, n))
#: and ``flags`` (int8, shape (N_FLAGS, n): ``limit`` and ``validity``), the rows of
#: :mod:`.rows`.
PointOut = namedtuple("PointOut", "design flags")

# ----------------------------------------------------------------- the closed loop
#: The shared supply and the sampling: ``dt`` [s], ``voltage`` [V],
#: ``internal_resistance`` [ohm], ``p_atm`` [Pa].
Supply = namedtuple("Supply", "dt voltage internal_resistance p_atm")

#: Per actuator (arrays (n,)): muscle length [m], r' [ohm/m], c' [J/(K m)], lambda'
#: [W/(K m)], ambient and initial temperature [K], stroke scale [-], eq. (2) shape.
Muscles = namedtuple("Muscles", "length r_per_len c_per_len loss_per_len t_amb t_start "
                                "stroke_scale gamma beta t_g sigma_g")

#: Per actuator: the plant's angle table (step [Pa], values [rad], slopes [rad/Pa]) and
#: the estimator's (step [Pa], values [rad]).
AngleTables = namedtuple("AngleTables", "plant_step plant_angles plant_slopes table_step "
                                        "tables")

#: Per actuator: half hysteresis band [rad], filter factor [-], reference [rad] and sensor
#: noise [Pa] at each sample; the controller ``kind`` (int64, 0 bang-bang, 1 PI), the PI's
#: ``gain`` [1/rad] and ``integral_step`` dt/T_i [-].
Control = namedtuple("Control", "half_band filter_keep reference noise kind gain "
                                "integral_step")

#: Outputs (n, m): temperature, stroke, pressure, angle, estimate, voltage, current, power.
SimOut = namedtuple("SimOut", "temperature stroke pressure angle estimate voltage current "
                              "power")

# ------------------------------------------------- one design's loop in a tracking sweep
#: One design's muscle in its closed loop (floats): the supply ``voltage`` [V], ``p_atm``
#: the initial chamber pressure [Pa], the muscle's ``length`` [m], ``r_per_len`` r'
#: [ohm/m], ``c_per_len`` c' [J/(K m)], ``loss_per_len`` lambda' [W/(K m)], ``t_amb`` and
#: ``t_start`` [K], ``stroke_scale`` s_max(C)/s_ref(T_max) [-], and eq. (2)'s ``gamma``
#: [1/K], ``beta`` [-], ``t_g`` and ``sigma_g`` [K].
LoopMuscle = namedtuple("LoopMuscle", "voltage p_atm length r_per_len c_per_len loss_per_len "
                                      "t_amb t_start stroke_scale gamma beta t_g sigma_g")

#: One design's plant: the actuator's ``length`` L [m] and its curvature table (the angle
#: is kappa L): ``step`` [Pa], ``kappa`` [1/m] and ``slope`` d kappa/dp [1/(m Pa)].
LoopPlant = namedtuple("LoopPlant", "length step kappa slope")

#: The estimator's table: ``step`` [Pa] and ``angles`` [rad].
Estimator = namedtuple("Estimator", "step angles")

#: The controller: ``kind`` (int, 0 bang-bang, 1 PI), ``half_band`` [rad], the PI's
#: ``gain`` [1/rad] and ``integral_step`` dt/T_i [-], the estimate's ``filter_keep`` [-].
LoopControl = namedtuple("LoopControl", "kind half_band gain integral_step filter_keep")

#: The reference: ``kind`` (int, 0 the sine mean + amplitude sin(2 pi frequency t +
#: phase), 1 the step from ``initial`` to ``final`` at ``at`` [s]), angles [rad]; the RMS
#: error counts the samples from ``rms_from`` [s].
LoopReference = namedtuple("LoopReference", "kind mean amplitude frequency phase initial "
                                            "final at rms_from")

#: The estimator table of one design: its ``section`` (a :class:`Section` [m]), the top
#: pressure ``p_top`` [Pa] (NaN: no loop), its ``points``, the ``silicone``
#: (:class:`Ogden`), the quadrature ``nodes`` (:class:`Nodes`) and the curvature solve's
#: ``rtol`` [-].
TableSpec = namedtuple("TableSpec", "section p_top points silicone nodes rtol")
