"""Named records that the orchestration formulas of :mod:`.limits` take (issue 28).

Plain :func:`collections.namedtuple` types, so that a group of values that always travel
together is one argument with named fields instead of a run of positional floats, where a
swapped pair would compile and run silently wrong. The uncompiled path builds them in
Python; the kernels build them in compiled code, where Numba passes a namedtuple as a tuple
with named fields and a field read costs nothing. The innermost formulas (stresses,
pressures, the curvature and stroke solves) keep their plain arguments. SI units.
"""

from __future__ import annotations

from collections import namedtuple

__all__ = ["CoilRow", "Cycle", "Drive", "NodeTable", "Nodes", "Ogden", "Reach",
           "SealedCoefficients", "Section", "SolvedCurve", "StrokeShape"]

#: The chamber's cross-section: inner ``radius`` a, ``wall`` thickness t and ``base``
#: (bottom layer) thickness b [m] (docs/model.md s. 1).
Section = namedtuple("Section", "radius wall base")

#: The muscle's free-stroke shape, eq. (2) (docs/model.md s. 9): ambient ``t_amb`` and
#: highest working temperature ``t_max`` [K], ``gamma`` [1/K], ``beta`` [-], the glass
#: transition ``t_g`` and its width ``sigma_g`` [K].
StrokeShape = namedtuple("StrokeShape", "t_amb t_max gamma beta t_g sigma_g")

#: The muscle's values at one coil index C: ``force_limit`` F_lim [N], the largest stroke
#: ``s_max`` [-], ``scale`` s_max over the stroke shape at T_max [-] (eq. 2), ``r_per_len``
#: r' [ohm/m], ``c_per_len`` c' [J/(K m)], ``loss_per_len`` lambda' [W/(K m)] and
#: ``force_coeff`` c of eq. (1) [N/K] (docs/model.md s. 9, 15).
CoilRow = namedtuple("CoilRow", "force_limit s_max scale r_per_len c_per_len loss_per_len "
                                "force_coeff")

#: Ogden constants of one silicone: ``mu`` [Pa] and ``alpha`` [-], one entry per term
#: (docs/model.md s. 5). The pointwise kernel's record of the same name holds 2-D arrays
#: (row, term); the formulas take one row.
Ogden = namedtuple("Ogden", "mu alpha")

#: Gauss-Legendre nodes and weights on [-1, 1] of the material moment: the base layer's
#: ``x_base``, ``w_base`` and each half disc's ``phi_trig`` (cos and sin of its nodes,
#: shape (2, n)) and ``w_phi`` [-] (:func:`~.bending.quadrature_nodes`).
Nodes = namedtuple("Nodes", "x_base w_base phi_trig w_phi")

#: A section's node table (:func:`~.bending._node_table`): node heights ``y`` [m] and
#: weights ``wy`` [m^3] and ``wyy`` (M_S = sum wy S, dM_S/dkappa = sum wyy S';
#: :func:`~.bending._section_nodes`), and the solver's scratch ``work`` (shape
#: (MOMENT_WORK_ROWS, n)).
NodeTable = namedtuple("NodeTable", "y wy wyy work")

#: Solved points of a section's kappa(p) that start later curvature solves
#: (:func:`~.bending._curvature_start`): ``pressure`` [Pa], ``kappa`` [1/m], ``rate``
#: dkappa/dp [1/(m Pa)] and ``rate2`` d2kappa/dp2 [1/(m Pa^2)]; the first ``n`` entries
#: count (``n`` passed beside it).
SolvedCurve = namedtuple("SolvedCurve", "pressure kappa rate rate2")

#: ``sealed_chamber``'s coefficients (docs/model.md s. 22, :mod:`.sealed`), dimensionless:
#: the chamber stiffness ``k0``, ``k1``, the rounding ``g0``, ``g1``, the squeeze ``c0``,
#: ``c1``, the blocked moment's ``cb`` (the squeeze's) and ``ca`` (the pressure's), and the
#: blocked pressure's ``r0`` .. ``r4`` (the chamber held straight). Every formula takes it
#: (the shipped one, or a sweep's ``chamber:``); the others' variants ignore it.
SealedCoefficients = namedtuple("SealedCoefficients", "k0 k1 g0 g1 c0 c1 cb ca r0 r1 r2 r3 r4")

#: The supply and the muscle it heats (:func:`~.limits._reach`): the supply ``voltage`` V
#: [V] (<= 0: none), the actuator's ``length`` L [m], the wrap angle ``wrap_angle`` psi
#: [rad] and the wrap's ``pitch`` [m], which set the muscle's length l_m and so its steady
#: temperature at V (docs/model.md s. 9, 15).
Drive = namedtuple("Drive", "voltage length wrap_angle pitch")

#: The muscle at its reachable temperature min(T_max, T_ss) (:func:`~.limits._reach`):
#: ``temperature`` [K], its free stroke ``s_free`` [-], the blocked force
#: ``force_blocked`` F_b = c (T - T_amb) [N] (``coupled_muscle``) and ``limited``, whether
#: the supply keeps the muscle below T_max (docs/model.md s. 15, 16).
Reach = namedtuple("Reach", "temperature s_free force_blocked limited")

#: What a design's heating cycle runs on (:func:`~.limits._dynamic_values`): the supply
#: ``voltage`` V [V] (<= 0: none), the design's ``thermal`` values (the six of
#: :func:`~.limits._thermal_values`: muscle length [m], resistance [ohm], heating power
#: [W], heating voltage [V], cooling time [s], heating time [s]), its working temperatures
#: ``temps`` (T*, T_5, T_95) [K] (:func:`~.limits._working_temperatures`), the ambient
#: ``t_amb`` [K] and the time constant ``tau`` = c'/lambda' [s] (docs/model.md s. 20).
Cycle = namedtuple("Cycle", "voltage thermal temps t_amb tau")
