"""The layout of the compiled wheelset's work arrays and codes: one place that names every row, column and code.

As in state.py, module-level integers are compile-time constants in numba: a kernel indexes ``rec[c, APPROACH]``
or ``g[NORMAL_Y]`` at no cost, and a reader sees what sits there. A new column is added here (its name in the
tuple of names and its constant, in the same order: tests/test_dynamics_layout.py checks both) and where it is
filled.

* The parameter record (``par``, :data:`PARAMETERS`, one numpy record of named float64 fields, SI units:
  :data:`PARAMETER_FIELDS`, with the track's fields from track.PARAMETER_FIELDS).
* The patch record (``rec``, (candidates + 2, :data:`N_FIELDS`)): one row per contact candidate with the
  :data:`PATCH_FIELDS` (what the results store per patch), then for ``auto`` the :data:`AUTO_PATCH_FIELDS`, then
  a formed patch's own quantities (:data:`FORMED_PATCH_FIELDS`, recorded in place of its candidate's); the
  last two rows hold the summed contact force per side (:data:`SIDE_FORCE_ROWS`, columns 0-2: x, y, z, main
  frame, N).
* The candidate geometry (``cg``, (candidates, :data:`N_GEO`)): :data:`GEOMETRY_FIELDS`, what the tables, the
  compiled 3-D search or a Python provider give the right-hand side per candidate.
* The contact-geometry table of providers.TableProvider (``table``, (:data:`N_TABLE_ROWS`, candidates, roll,
  lateral)): :data:`TABLE_FIELDS`.
* The running-direction section's result per candidate (:data:`SECTION_FIELDS`; compiled_tables._irregularity).
* The scratch rows of the right-hand side (``sc``, (:data:`N_SCRATCH`, 3)): :data:`SCRATCH_ROWS`.
* The codes: the candidate geometry's source (:data:`GEOMETRY_TABLES`, ...) and the one status table of every
  compiled loop and right-hand side (:data:`STATUS`: code -> run status and what happened). The codes of the
  compiled contact laws are compiled_laws.LAW_CODES.
"""

from __future__ import annotations

import numpy as np

from rigid_dynamics.wheelset import track

# --- the patch record: columns per candidate -----------------------------------------------------------------------
PATCH_FIELDS = (
    "normal_force_N",
    "creep_force_long_N",
    "creep_force_lat_N",
    "spin_moment_Nm",
    "creepage_long",
    "creepage_lat",
    "spin_creepage_1_per_m",
    "approach_m",
    "contact_point_y_m",
    "wheel_lateral_m",
    "rolling_radius_m",
    "contact_angle_rad",
    "semi_axis_long_m",
    "semi_axis_lat_m",
    "contact_area_m2",
    "max_pressure_Pa",
    "patch_geometry_code",
    "ellipticity_residual",
    "contact_law_code",
)
"""Per-patch quantities recorded in the results, each of shape (n_out, 2 sides, 2 slots). ``patch_geometry_code`` says
which geometry the contact model saw (:data:`PATCH_ELLIPSE`: the quadric of the curvatures at the contact point;
:data:`PATCH_SAMPLED`: the undeformed distance sampled from the real surfaces), ``ellipticity_residual`` how far a
sampled gap departs from that quadric (rigid_dynamics.contact.search.ellipticity_error; NaN for an ellipse) and
``contact_law_code`` which law served the patch (its code in compiled_laws.LAW_CODES; LAW_CALLBACK for a model solved
through the callback)."""
(
    NORMAL_FORCE, CREEP_FORCE_LONG, CREEP_FORCE_LAT, SPIN_MOMENT, CREEPAGE_LONG, CREEPAGE_LAT, SPIN_CREEPAGE,
    APPROACH, CONTACT_POINT_Y, WHEEL_LATERAL, ROLLING_RADIUS, CONTACT_ANGLE, SEMI_AXIS_LONG, SEMI_AXIS_LAT,
    CONTACT_AREA, MAX_PRESSURE, PATCH_GEOMETRY, ELLIPTICITY_RESIDUAL, CONTACT_LAW,
) = range(19)  # fmt: skip
N_PATCH = 19

PATCH_ELLIPSE, PATCH_SAMPLED = range(2)
"""Codes of the ``patch_geometry_code`` column: the quadric (multi-Hertzian) or the sampled undeformed distance."""
PATCH_GEOMETRY_NAMES = ("ellipse", "sampled")

AUTO_PATCH_FIELDS = (
    "auto_rung",
    "auto_level",
    "auto_deciding_feature",
    "auto_deciding_threshold",
    "auto_saturation",
    "auto_spin_share",
    "auto_ellipticity_residual",
    "auto_curvature_change",
    "auto_second_patch_nearness",
)
"""Per-patch record of the ``auto`` model's choice (runs with contact_model "auto" only): ``auto_rung`` the index of
the chosen rung in rigid_dynamics.contact.auto.AUTO_RUNGS, ``auto_level`` the tolerance level used (NaN: below every
level), ``auto_deciding_feature`` the index in auto.FEATURES of the feature whose threshold decided (-1: none) and
that threshold, then the patch's features (rigid_dynamics.contact.auto.patch_features)."""
AUTO_RUNG, AUTO_LEVEL, AUTO_DECIDING_FEATURE, AUTO_DECIDING_THRESHOLD, AUTO_FEATURES = range(N_PATCH, N_PATCH + 5)
"""Columns of the auto record; AUTO_FEATURES is the first of the five features (AUTO_FEATURE_NAMES' order)."""
N_FORMED = 12
"""The patch record's first columns (normal force to contact angle) that a formed patch gives in its own frame."""
FORMED_PATCH_FIELDS = tuple(f"formed_{name}" for name in PATCH_FIELDS[:N_FORMED])
"""Per candidate that serves a formed patch (wheelset/formed_patches.py: a gap-solving model with patches formed as
CONTACT's module 1 forms them): the formed patch's own quantities in place of PATCH_FIELDS[:N_FORMED], which hold the
candidate's (the forces the loop applies, in the candidate's contact frame, and its geometry and creepages): N', T_x',
T_y' and M_z' in the formed patch's contact frame, the creepages transported to its reference point, its approach,
the reference point's y (main frame), the wheel's lateral coordinate and rolling radius there and its contact angle.
NaN (``formed_normal_force_N`` NaN) for any other candidate. Not results of their own: the record writers put them
in place of the candidate's (formed_patches.recorded)."""
N_FRAME_MAP = 12
"""Values of the map from a candidate's contact frame to the formed patch's it serves (formed_patches.frame_map: the
3 x 3 direction cosines and the offset's moment arm), which ``auto``'s anchors keep (auto_reuse.reuse_own)."""
NOT_FORMED = (float("nan"),) * N_FORMED
"""The own quantities of a candidate that served no formed patch (compiled_rhs.CallbackOutcome.own, and of every
patch a compiled law solved or an anchor not formed served: auto_reuse.reuse_own)."""
NOT_MAPPED = (float("nan"),) * N_FRAME_MAP
"""The frame map of a candidate that served no formed patch (compiled_rhs.CallbackOutcome.frame_map)."""
FORMED = N_PATCH + len(AUTO_PATCH_FIELDS)
"""The first column of the formed patch's own quantities: rec[c, FORMED + k] is PATCH_FIELDS[k]'s, k < N_FORMED."""
N_FIELDS = FORMED + N_FORMED


def record_columns(auto: bool) -> list[tuple[int, str]]:
    """(column of the patch record, field name) of what a run records per candidate: PATCH_FIELDS, AUTO_PATCH_FIELDS
    for ``auto``, and FORMED_PATCH_FIELDS (formed_patches.recorded puts them in place of the candidate's).
    """
    columns = list(enumerate(PATCH_FIELDS))
    if auto:
        columns += [(N_PATCH + k, name) for k, name in enumerate(AUTO_PATCH_FIELDS)]
    return columns + [(FORMED + k, name) for k, name in enumerate(FORMED_PATCH_FIELDS)]


SIDE_FORCE_ROWS = 2
"""Rows after the candidates' rows: the summed contact force on the left and the right wheel."""

MAX_SLOTS = 2
"""Patches per wheel in the results (tread, flange or second)."""

AUTO_FEATURE_NAMES = ("saturation", "spin_share", "ellipticity_residual", "curvature_change", "second_patch_nearness")
"""auto's features in the order of the compiled thresholds (contact.auto.FEATURES' names)."""
AUTO_RUNG_NAMES = ("linear", "vermeulen_johnson", "fastsim")
"""auto's compiled rungs in the order of the parameter record's thresholds; rung 3 (:data:`AUTO_BEM`) is BEM."""
AUTO_LINEAR, AUTO_VERMEULEN_JOHNSON, AUTO_FASTSIM, AUTO_BEM, AUTO_BEM_CORRECTED = range(5)
"""AUTO_BEM_CORRECTED: a BEM patch served by FASTSIM corrected by its stored BEM solution (wheelset/auto_reuse.py)."""

# --- the candidate geometry ------------------------------------------------------------------------------------------
GEOMETRY_FIELDS = (
    "approach_m",
    "lever_x_m",
    "lever_y_m",
    "lever_z_m",
    "normal_x",
    "normal_y",
    "normal_z",
    "curvature_long_1_per_m",
    "curvature_lat_1_per_m",
    "rolling_radius_m",
    "wheel_lateral_m",
    "contact_angle_rad",
    "ellipse_angle_rad",
)
"""Per candidate: approach q (NaN: absent), the contact point less the wheelset centre (main frame), the contact
normal (rail into wheel), the relative curvatures A (rolling direction) and B, rolling radius, the wheel's lateral
coordinate y_d of the point, contact angle, and the angle from the rolling direction to A's principal axis (the
search's; 0 where the geometry has none: tables, given)."""
(
    G_APPROACH, G_LEVER, _G_LEVER_Y, _G_LEVER_Z, G_NORMAL, _G_NORMAL_Y, _G_NORMAL_Z, G_CURVATURE_LONG,
    G_CURVATURE_LAT, G_ROLLING_RADIUS, G_WHEEL_LATERAL, G_CONTACT_ANGLE, G_ELLIPSE_ANGLE,
) = range(13)  # fmt: skip
"""G_LEVER and G_NORMAL are the first of their three components (x, y, z)."""
N_GEO = 13

# --- the contact-geometry table of providers.TableProvider -----------------------------------------------------------
TABLE_FIELDS = (
    "approach_m",
    "approach_per_height",
    "point_y_m",
    "point_z_m",
    "normal_y",
    "normal_z",
    "curvature_long_1_per_m",
    "curvature_lat_1_per_m",
    "rolling_radius_m",
    "contact_angle_rad",
    "wheel_lateral_m",
    "merge_gap_m",
)
"""Rows of the table per candidate over (roll, lateral shift): the approach at z_ref and its rate dq/dz (= -n_z),
the contact point relative to the centre (y) and to z_ref (z), the normal's y and z, the curvatures, rolling radius,
contact angle, the wheel's lateral coordinate, and for a slot > 0 the gap between the two candidates (> 0:
merged with slot 0, dropped)."""
(
    T_APPROACH, T_APPROACH_PER_HEIGHT, T_POINT_Y, T_POINT_Z, T_NORMAL_Y, T_NORMAL_Z, T_CURVATURE_LONG,
    T_CURVATURE_LAT, T_ROLLING_RADIUS, T_CONTACT_ANGLE, T_WHEEL_LATERAL, T_MERGE_GAP,
) = range(12)  # fmt: skip
N_TABLE_ROWS = 12

# --- the running-direction section of one candidate ------------------------------------------------------------------
SECTION_FIELDS = (
    "approach_m",
    "offset_x_m",
    "offset_z_m",
    "normal_x",
    "normal_y",
    "normal_z",
    "rolling_radius_m",
    "curvature_long_1_per_m",
)
"""The irregular candidate (compiled_tables.irregular_candidates): approach, the contact point's offset along x and
z from the ideal one, the tilted normal, the rolling radius and the longitudinal curvature A at the section."""
(
    I_APPROACH, I_OFFSET_X, I_OFFSET_Z, I_NORMAL_X, I_NORMAL_Y, I_NORMAL_Z, I_ROLLING_RADIUS, I_CURVATURE_LONG,
) = range(8)  # fmt: skip
N_SECTION = 8

# --- the scratch rows of the right-hand side (no allocation in the loop) ---------------------------------------------
SCRATCH_ROWS = (
    "normal",
    "lever",
    "point_velocity",
    "ex",
    "ey",
    "patch_force",
    "patch_moment",
    "total_force",
    "total_moment",
    "side_force_left",
    "side_force_right",
    "omega",
    "rotation_row_0",
    "rotation_row_1",
    "rotation_row_2",
    "search_centre",
    "omega_absolute",
)
"""Rows of 3 of the right-hand side's scratch array: per patch (normal, lever, the point's velocity, the contact
frame, its force and moment), the sums, the side forces, omega and R_z R_x (3 rows), the elastic search's centre,
the absolute angular velocity in a curve."""
(
    S_NORMAL, S_LEVER, S_POINT_VELOCITY, S_EX, S_EY, S_PATCH_FORCE, S_PATCH_MOMENT, S_TOTAL_FORCE, S_TOTAL_MOMENT,
    S_SIDE_FORCE, _S_SIDE_FORCE_RIGHT, S_OMEGA, S_ROTATION, _S_ROTATION_1, _S_ROTATION_2, S_SEARCH_CENTRE,
    S_OMEGA_ABSOLUTE,
) = range(17)  # fmt: skip
"""S_SIDE_FORCE and S_ROTATION are the first of their 2 and 3 rows."""
N_SCRATCH = 17

# --- codes -----------------------------------------------------------------------------------------------------------
GEOMETRY_TABLES, GEOMETRY_SEARCH, GEOMETRY_GIVEN = range(3)
"""Where the right-hand side's candidate geometry comes from: the compiled tables (with the running-direction
irregularities), the compiled 3-D search, or given by the caller (a provider the compiled code does not evaluate)."""

OK, BLOW_UP, FORCE_ANOMALY, DERAILED, CREEPAGES_UNDEFINED, CALLBACK_FAILED, UNDERFLOW, GAP_LAW_FAILED = range(8)
STATUS = {
    OK: ("ok", "ok"),
    BLOW_UP: ("blow-up", "a state is not finite"),
    FORCE_ANOMALY: ("force-anomaly", "a wheel's normal force exceeds max_force_factor x the static wheel load"),
    DERAILED: ("derailed", "the lateral displacement exceeds max_lateral_displacement_m"),
    CREEPAGES_UNDEFINED: ("contact-failed", "the creepages are undefined (no rolling speed at a patch)"),
    CALLBACK_FAILED: ("contact-failed", "the contact model behind the callback failed"),
    UNDERFLOW: ("step-size-underflow", "the error-controlled step fell below its smallest size"),
    GAP_LAW_FAILED: (
        "contact-failed",
        "KPEC put pressure on no element of a sampled gap that overlaps (its equivalent ellipse misses the deepest "
        "row)",
    ),
}
"""The one status table of the compiled right-hand side and loops: code -> (run status, what happened)."""


def status_name(code: int) -> str:
    """The run status of a compiled status code (:data:`STATUS`)."""
    return STATUS[int(code)][0]


# --- the parameter record ------------------------------------------------------------------------------------------
PARAMETER_FIELDS = (
    ("mass_kg", "wheelset mass"),
    ("inertia_transverse_kg_m2", "roll/yaw moment of inertia (body frame)"),
    ("inertia_axial_kg_m2", "spin moment of inertia"),
    ("gravity_m_per_s2", "gravity, z down"),
    ("suspension_kx_N_per_m", "primary stiffness x per side"),
    ("suspension_ky_N_per_m", "primary stiffness y per side"),
    ("suspension_kz_N_per_m", "primary stiffness z per side"),
    ("suspension_cx_N_s_per_m", "primary damping x per side"),
    ("suspension_cy_N_s_per_m", "primary damping y per side"),
    ("suspension_cz_N_s_per_m", "primary damping z per side"),
    ("yaw_stiffness_N_m_per_rad", "yaw stiffness per side"),
    ("yaw_damping_N_m_s_per_rad", "yaw damping per side"),
    ("suspension_half_spacing_m", "lateral half spacing of the springs"),
    ("frame_z_m", "frame height (spring attachment)"),
    ("frame_x0_m", "frame x at t = 0 (moves at speed_m_per_s)"),
    ("frame_yaw_rad", "the frame's held yaw (its points at (x_frame - s b sin, s b cos))"),
    ("speed_m_per_s", "running speed"),
    ("axle_load_N", "axle load, z down"),
    ("torque_N_m", "driving/braking torque about the axle"),
    ("shear_modulus_Pa", "combined shear modulus G"),
    ("contact_modulus_Pa", "E* of Hertz"),
    ("friction_coefficient", "friction coefficient"),
    ("model_code", "compiled_laws.LAW_CODES value: the compiled law, or the callback"),
    ("z_ref_m", "table reference centre height"),
    ("max_force_N", "force anomaly limit"),
    ("max_lateral_m", "derailment limit |y|"),
    ("fastsim_nx", "FASTSIM elements per strip"),
    ("fastsim_ny", "FASTSIM strips"),
    ("fastsim_parabolic", "1: parabolic traction bound"),
    ("kpec_nx", "KPEC in the loop: grid points (element centres) along x of the sampled gap"),
    ("kpec_ny", "KPEC in the loop: grid points along y"),
    ("kpec_margin", "KPEC in the loop: the grid's margin around the rigid overlap, fraction of its extent"),
    ("patch_sampled", "1: a gap-solving compiled law sees the sampled gap (search), 0: the quadric (ellipse)"),
    ("flexibility_code", "contact.fastsim.FLEXIBILITY_CODES value"),
    ("irregular", "1: running-direction irregularities on"),
    ("nominal_radius_m", "nominal rolling radius"),
    ("polygon_order", "polygon order"),
    ("polygon_amplitude_m", "polygon amplitude"),
    ("polygon_phase_rad", "polygon phase"),
    ("flat_length_m", "flat length"),
    ("flat_depth_m", "flat depth"),
    ("flat_angle_rad", "flat position"),
    ("corrugation_wavelength_m", "corrugation wavelength"),
    ("corrugation_amplitude_m", "corrugation amplitude"),
    ("irregular_left", "1: left side irregular"),
    ("irregular_right", "1: right side irregular"),
    ("irregularity_reach_m", "gap beyond which a candidate is left alone"),
    ("section_half_angle_rad", "half range of the running-direction section"),
    *track.PARAMETER_FIELDS,
    ("dip_angle_rad", "joint dip angle"),
    ("dip_position_m", "joint position"),
    ("dip_ramp_length_m", "joint ramp length"),
    ("dip_entry_rounding_m", "joint entry rounding"),
    ("dip_rounding_m", "joint rounding"),
    ("track_frame", "1: curve or cant: the track-following frame's terms (compiled_motion, compiled_rhs) are on"),
    ("curvature_1_per_m", "signed curvature of the centreline, +1/R right curve"),
    ("cant_sin", "sin of the signed cant angle (> 0: left rail higher)"),
    ("cant_cos", "cos of the cant angle"),
    ("carried_mass_kg", "axle load / g: the mass whose quasi-static gravity and centrifugal load acts at the axle"),
    ("auto_level", "auto: the tolerance level whose thresholds apply (NaN: below every level, always BEM)"),
    ("auto_friction_bound_tolerance", "auto: FASTSIM above (1 + this) mu N is replaced by BEM (models.py)"),
    ("auto_fastsim_table", "auto: 1: its FASTSIM rung served by FASTSIM's creep-force table (scene key creep_table)"),
    ("auto_reuse", "auto: 1: its BEM patches reused within a trust region (auto_reuse.py; scene key auto_reuse)"),
    *(
        (f"auto_{r}_{f}", f"auto: threshold of {f} for {r} (NaN: no measured box)")
        for r in AUTO_RUNG_NAMES
        for f in AUTO_FEATURE_NAMES
    ),
)
"""The parameter record of the compiled right-hand side: (field, meaning); every field float64, SI units."""

PARAMETERS = np.dtype([(n, np.float64) for n, _ in PARAMETER_FIELDS])
"""numpy structured dtype of the parameter record: numba compiles ``par.mass_kg`` to a load at a fixed offset.
Chosen by measured overhead: a kernel reading 16 parameters, called 2e7 times in a compiled loop, took 49.8 ns per
call with a float vector and index constants, 49.2 ns with the structured record, 48.2 ns with a jitclass and 51.7 ns
with a structref (one session, noise ~5 %): no difference; the record keeps numba's on-disk cache working (a jitclass
or structref argument made every new process recompile)."""


def new_parameters():
    """A zeroed parameter record (a numpy record of :data:`PARAMETERS`; set fields as ``par["mass_kg"] = ...``)."""
    return np.zeros(1, PARAMETERS)[0]
