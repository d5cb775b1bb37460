"""The velocity columns of the wheelset's Jacobian from the creep-force sensitivities (offered and checked).

The state's velocities (x', y', z', psi', theta', phi') reach the contact forces in two ways: through the contact
frame (e_x follows the rolling velocity, so the frame turns with it) and through the creepages (xi, eta, phi) of
every patch (eq 39-49, compiled_motion._patch_creepages); the normal force and the patch geometry depend on the
positions only (rigid track). So, with R(y, T) the right-hand side with the patches' forces T_p = (Tx, Ty, Mz)
held (the frames, levers and normal forces as at y)::

    df/dv_j = dR/dv_j |_T  +  sum_p  dR/dT_p  S_p  dc_p/dv_j

with S_p = d(Tx, Ty, Mz)/d(xi, eta, phi) the rung's sensitivities at the patch's operating point
(rigid_dynamics.contact.sensitivities: Kalker's coefficients and the saturation's derivative for the analytic
rungs, central differences for the others), dc_p/dv_j by central differences of the creepage kernel (smooth,
cheap) and the two R terms by differences of the assembly (compiled_motion._assemble, which is affine in the
forces). No right-hand side of the rung is differenced in the velocities.

What it leaves out, said: the rung's dependence on the rolling speed V at fixed creepages (a falling friction law,
which slows with the slip velocity V |s|), and for a compiled law the difference between its tables (Hertz and
Kalker by tables, compiled_laws) and the Python rung that gives S_p (the table interpolation, 1e-4 relative or
below). Only the straight rigid track (the elastic track's rail velocities and a curve's frame enter the
creepages as further terms): elsewhere :func:`creep_velocity_columns` raises ValueError.

Used by Radau and BDF for a rung the loop calls back (drivers.sensitivity_velocity_columns: the BEM's differences
are noise there); benchmarks/bench_creep_sensitivities.py measures the columns against differences (accuracy and
time per rung), bench_radau_bem_jacobian.py a Radau run with each; tests/test_creep_jacobian.py checks the assembly
against the model's right-hand side and the columns against differences.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from rigid_dynamics.wheelset.compiled_motion import _assemble, _patch_creepages, _rotation
from rigid_dynamics.wheelset.layout import (
    CREEP_FORCE_LAT,
    CREEP_FORCE_LONG,
    G_APPROACH,
    G_CURVATURE_LAT,
    G_CURVATURE_LONG,
    G_LEVER,
    G_NORMAL,
    NORMAL_FORCE,
    SPIN_MOMENT,
)
from rigid_dynamics.wheelset.state import VELOCITIES

FORCE_COLUMNS = ("creep_force_long_N", "creep_force_lat_N", "spin_moment_Nm")
"""The held patch quantities T_p (contact frame, on the wheel)."""


@dataclass(frozen=True, eq=False)
class CreepColumns:
    """d f / d (x', y', z', psi', theta', phi') of a wheelset model's right-hand side from the sensitivities.

    Attributes:
        columns: (n_state, 6) array, SI units (rows: the full state's rates; columns: the velocities in order).
        sensitivities: the CreepSensitivities of each patch in contact (order of the model's candidates).
        patches: the patches in contact.
        wall_time_s: s.
    """

    columns: np.ndarray
    sensitivities: tuple
    patches: int
    wall_time_s: float


class _Patches:
    """The patches in contact at a state: geometry and held forces (arrays over patches)."""

    def __init__(self, model, full):
        model.contact(full[:12], record=True, keep_search_memory=True)
        present = np.flatnonzero(~np.isnan(model._cg[:, G_APPROACH]))
        cg, rec = model._cg[present], model._rec[present]
        active = np.nan_to_num(rec[:, NORMAL_FORCE], nan=0.0) > 0
        self.cg = cg[active]
        self.lever = np.ascontiguousarray(self.cg[:, G_LEVER : G_LEVER + 3])
        self.normal = np.ascontiguousarray(self.cg[:, G_NORMAL : G_NORMAL + 3])
        self.forces = np.stack([rec[active, k] for k in (CREEP_FORCE_LONG, CREEP_FORCE_LAT, NORMAL_FORCE, SPIN_MOMENT)],
                               axis=1)  # fmt: skip

    def __len__(self):
        return len(self.lever)


def _creepages(full, lever, normal):
    """(V, xi, eta, phi) of one patch at the full state (the compiled kernel; rigid track)."""
    om, rzx = np.empty(3), np.empty((3, 3))
    _rotation(full, om, rzx)
    vel, ex, ey = np.empty(3), np.empty(3), np.empty(3)
    return np.array(_patch_creepages(lever, normal, om, full[6], full[7], full[8], 0.0, 0.0, vel, ex, ey))


def held_rates(model, t: float, full: np.ndarray, patches: _Patches, forces: np.ndarray) -> np.ndarray:
    """R(y, T): the right-hand side at ``full`` with the patches' (Tx, Ty, N, Mz) = ``forces`` (k, 4) held, in the
    contact frames the velocities at ``full`` give (compiled_rhs._forces' assembly, straight rigid track).
    """
    om, rzx = np.empty(3), np.empty((3, 3))
    _rotation(full, om, rzx)
    vel, ex, ey = np.empty(3), np.empty(3), np.empty(3)
    force, moment, p_con = np.zeros(3), np.zeros(3), 0.0
    for p in range(len(patches)):
        lever, n = patches.lever[p], patches.normal[p]
        _patch_creepages(lever, n, om, full[6], full[7], full[8], 0.0, 0.0, vel, ex, ey)
        tx, ty, normal, mz = forces[p]
        fc = ex * tx + ey * ty + n * normal
        mc = n * mz
        force += fc
        moment += np.cross(lever, fc) + mc
        p_con += float(fc @ vel + mc @ om)
    out = np.empty(model.n_state)
    model.par["frame_x0_m"] = model.frame_x0
    _assemble(float(t), full, model.par, force, moment, p_con, (0.0, 0.0, 0.0, 0.0), om, rzx, out)
    return out


def _check_supported(model) -> None:
    if model.elastic:
        raise ValueError("creep_velocity_columns: the elastic track (its rail velocities enter the creepages): "
                         "expected a scene on the rigid track")  # fmt: skip
    if model.par["track_frame"] > 0:
        raise ValueError("creep_velocity_columns: a curve's frame (its rates enter the creepages): expected a "
                         "straight track")  # fmt: skip


def creep_velocity_columns(model, t: float, state: np.ndarray, relative_step: float | None = None) -> CreepColumns:
    """The velocity columns of ``model``'s Jacobian at the full ``state`` (module docstring), with the sensitivities
    of the model's own rung and options at each patch (central differences with ``relative_step`` x the creepage
    scale where the rung has no closed form, None: the rung's default; one step, no dF/dN).

    Raises:
        ValueError: elastic track or curve (module docstring); a patch whose sensitivities failed (its message).
    """
    from rigid_dynamics.contact.sensitivities import OperatingPoint, creep_sensitivities
    from rigid_dynamics.contact.types import ContactGeometry, Creepage

    start = time.perf_counter()
    _check_supported(model)
    full = np.array(state, float)
    patches = _Patches(model, full)
    held = patches.forces
    columns = np.zeros((model.n_state, 6))
    velocity = range(VELOCITIES.start, VELOCITIES.stop)
    steps = [1e-6 * max(1.0, abs(full[j])) for j in velocity]
    for k, j in enumerate(velocity):  # the frames, levers and assembly with the forces held
        plus, minus = full.copy(), full.copy()
        plus[j] += steps[k]
        minus[j] -= steps[k]
        columns[:, k] = (held_rates(model, t, plus, patches, held) - held_rates(model, t, minus, patches, held)) / (
            2.0 * steps[k]
        )
    sensitivities = []
    for p in range(len(patches)):
        speed, xi, eta, spin = _creepages(full, patches.lever[p], patches.normal[p])
        g = patches.cg[p]
        point = OperatingPoint(
            ContactGeometry(float(g[G_CURVATURE_LONG]), float(g[G_CURVATURE_LAT]), float(g[G_APPROACH])),
            Creepage(float(xi), float(eta), float(spin), float(speed)),
            model.scene.material,
            None,
            model.model_options,
        )
        sens = creep_sensitivities(model.model, point, relative_step=relative_step, estimate_error=False, normal=False)
        if not sens.success:
            raise ValueError(f"patch {p}: {sens.status}: {sens.message}")
        sensitivities.append(sens)
        s = np.nan_to_num(sens.jacobian[:, :3])  # a rung without a spin moment: its Mz row is 0
        by_force = np.empty((model.n_state, 3))  # dR/d(Tx, Ty, Mz): R is affine in them (difference exact)
        for i, slot in enumerate((0, 1, 3)):
            unit = max(1.0, abs(held[p, 2]))
            up, down = held.copy(), held.copy()
            up[p, slot] += unit
            down[p, slot] -= unit
            by_force[:, i] = (held_rates(model, t, full, patches, up) - held_rates(model, t, full, patches, down)) / (
                2.0 * unit
            )
        d_creep = np.empty((3, 6))  # d(xi, eta, phi)/dv
        for k, j in enumerate(velocity):
            plus, minus = full.copy(), full.copy()
            plus[j] += steps[k]
            minus[j] -= steps[k]
            up = _creepages(plus, patches.lever[p], patches.normal[p])[1:]
            down = _creepages(minus, patches.lever[p], patches.normal[p])[1:]
            d_creep[:, k] = (up - down) / (2.0 * steps[k])
        columns += by_force @ s @ d_creep
    return CreepColumns(columns, tuple(sensitivities), len(patches), time.perf_counter() - start)


def difference_velocity_columns(model, t: float, state: np.ndarray, rel_step: float = 1e-7) -> np.ndarray:
    """The same columns by central differences of the model's right-hand side (the reference of the check), step
    ``rel_step`` max(1, |v_j|).
    """
    full = np.array(state, float)
    columns = np.zeros((model.n_state, 6))
    for k, j in enumerate(range(VELOCITIES.start, VELOCITIES.stop)):
        h = rel_step * max(1.0, abs(full[j]))
        plus, minus = full.copy(), full.copy()
        plus[j] += h
        minus[j] -= h
        columns[:, k] = (model.derivative(t, plus) - model.derivative(t, minus)) / (2.0 * h)
    return columns


def relative_difference(columns: np.ndarray, reference: np.ndarray) -> float:
    """Max over the rows 6-11 (accelerations) of |difference| / max |reference| of that row."""
    rows = slice(6, 12)
    scale = np.max(np.abs(reference[rows]), axis=1)
    scale = np.where(scale > 0, scale, 1.0)
    return float(np.max(np.max(np.abs(columns[rows] - reference[rows]), axis=1) / scale))
