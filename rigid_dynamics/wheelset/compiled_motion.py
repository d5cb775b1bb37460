"""The equations of motion of the compiled right-hand side (numba): creepages of a patch, Newton and Euler with the
suspension, the curve's track-following frame and the track's equations.

* Creepages (:func:`_patch_creepages`, eq 39-49; the formulas of contact.creepage).
* The equations of motion (:func:`_assemble`: eq 59-71 with the gyroscopic term, the primary suspension to a frame
  moving at the running speed, the yaw springs, the driving torque; the track's equations are those of
  :mod:`rigid_dynamics.wheelset.track`: a track model is added there, in state.py's layout and in :func:`_assemble`'s
  call).
* Curves and cant (scene ``[track] curve_direction``, ``curve_radius_m``, ``cant_m``; ``par.track_frame``): the
  states are relative to a frame following the track; :func:`_assemble_curve` adds the frame's terms to Newton and
  Euler (compiled_rhs._forces takes the creepages from the absolute velocities; straight track without cant: the
  code path of before).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from rigid_dynamics.wheelset.state import (
    ROLL,
    ROLL_RATE,
    SPIN,
    SPIN_RATE,
    WORK_CONTACT,
    WORK_EXTERIOR,
    X_VELOCITY,
    Y_VELOCITY,
    YAW,
    YAW_RATE,
    Z_VELOCITY,
    X,
    Y,
    Z,
)
from rigid_dynamics.wheelset.track import track_rates as _track_rates

SPEED_ROW, XI_ROW, ETA_ROW, SPIN_ROW = range(4)
"""Rows of :func:`patch_creepages`' output (4, n): the rolling speed V (m/s), xi, eta (-) and the spin (1/m)."""
VERTICAL_LEFT, VERTICAL_RIGHT, LATERAL_LEFT, LATERAL_RIGHT = range(4)
"""Entries of :func:`track_rates`' rail forces (N): vertical left, right, then (the lateral track) lateral left,
right."""


@njit(cache=True, _nrt=False)
def _patch_creepages(lever, n, om, vx, vy, vz, rail_vy, rail_vz, vel, ex, ey):
    """Contact frame and creepages of one patch (eq 39-49; the formulas of contact.creepage): e_x = v_p/|v_p| with
    v_p the rolling velocity [x', 0, 0] projected on the contact plane, e_y = n x e_x; V = |v_p|; xi = v_w . e_x / V,
    eta = v_w . e_y / V, spin = omega . n / V with v_w = x_t' + omega x r_con (eq 44) less the rail's vertical
    velocity ``rail_vz`` and lateral velocity ``rail_vy``. Fills vel (v_w), ex, ey; returns (V, xi, eta, spin); V
    not > 0: creepages undefined
    (xi, eta, spin 0, ex, ey not set).
    """
    vel[0] = vx + om[1] * lever[2] - om[2] * lever[1]
    vel[1] = vy + om[2] * lever[0] - om[0] * lever[2]
    vel[2] = vz + om[0] * lever[1] - om[1] * lever[0]
    vel[1] -= rail_vy
    vel[2] -= rail_vz
    nv = n[0] * vx
    vp0, vp1, vp2 = vx - nv * n[0], 0.0 - nv * n[1], 0.0 - nv * n[2]
    speed = math.sqrt(vp0**2 + vp1**2 + vp2**2)
    if not speed > 0.0:
        return speed, 0.0, 0.0, 0.0
    ex[0], ex[1], ex[2] = vp0 / speed, vp1 / speed, vp2 / speed
    ey[0] = n[1] * ex[2] - n[2] * ex[1]
    ey[1] = n[2] * ex[0] - n[0] * ex[2]
    ey[2] = n[0] * ex[1] - n[1] * ex[0]
    xi = (vel[0] * ex[0] + vel[1] * ex[1] + vel[2] * ex[2]) / speed
    eta = (vel[0] * ey[0] + vel[1] * ey[1] + vel[2] * ey[2]) / speed
    spin = (om[0] * n[0] + om[1] * n[1] + om[2] * n[2]) / speed
    return speed, xi, eta, spin


@njit(cache=True)
def patch_creepages(lever, normal, om, v_c, rail_vy, rail_vz, frames, out):
    """:func:`_patch_creepages` of n patches for the Python right-hand side: lever, normal (n, 3), angular velocity
    om (3), centre velocity v_c (3), rail lateral and vertical velocity per patch (n); frames (n, 3, 3) get the
    columns e_x, e_y, n, out (4, n) the rows V, xi, eta, spin (NaN where V is not > 0).
    """
    vel, ex, ey = np.empty(3), np.empty(3), np.empty(3)
    for k in range(lever.shape[0]):
        speed, xi, eta, spin = _patch_creepages(
            lever[k], normal[k], om, v_c[0], v_c[1], v_c[2], rail_vy[k], rail_vz[k], vel, ex, ey
        )
        if not speed > 0.0:
            xi = eta = spin = ex[0] = ex[1] = ex[2] = ey[0] = ey[1] = ey[2] = np.nan
        out[SPEED_ROW, k], out[XI_ROW, k], out[ETA_ROW, k], out[SPIN_ROW, k] = speed, xi, eta, spin
        for i in range(3):
            frames[k, i, 0], frames[k, i, 1], frames[k, i, 2] = ex[i], ey[i], normal[k, i]


@njit(cache=True, _nrt=False)
def _j_times(rzx, jb0, jb1, jb2, v0, v1, v2):
    """J v with J = R J_body R^T (R = R_z R_x, J_body = diag(jb0, jb1, jb2))."""
    b0 = rzx[0, 0] * v0 + rzx[1, 0] * v1 + rzx[2, 0] * v2
    b1 = rzx[0, 1] * v0 + rzx[1, 1] * v1 + rzx[2, 1] * v2
    b2 = rzx[0, 2] * v0 + rzx[1, 2] * v1 + rzx[2, 2] * v2
    return (
        rzx[0, 0] * jb0 * b0 + rzx[0, 1] * jb1 * b1 + rzx[0, 2] * jb2 * b2,
        rzx[1, 0] * jb0 * b0 + rzx[1, 1] * jb1 * b1 + rzx[1, 2] * jb2 * b2,
        rzx[2, 0] * jb0 * b0 + rzx[2, 1] * jb1 * b1 + rzx[2, 2] * jb2 * b2,
    )


@njit(cache=True, _nrt=False)
def _assemble_curve(y, par, force, moment, fe, me, om, rzx, p_ext):
    """Newton and Euler in the track-following frame of a curve with cant (scene [track] curve_*, cant_m): the
    translational and angular accelerations relative to that frame, and ``p_ext`` plus the power the frame's terms
    add (returned: acc0, acc1, acc2, al0, al1, al2, p_ext). fe, me: the exterior force and moment (3-tuples).

    The frame F(x) sits at the arc length x of the track centreline (rail level), axes t (along the track), n (in the
    canted track plane, to the right), b (normal to it, down); the states are relative to it (x: arc length; y, z:
    the centre's offset from the centreline point in F; yaw, roll: Euler angles relative to F). The true vertical
    (down) in F is e_V = (0, sin c, cos c) with c the signed cant angle (> 0: left rail higher). F turns about e_V at
    Omega = kappa x' e_V (kappa = +-1/R, > 0 for a right curve). With r_c = (0, y, z) the centre's velocity is
    v = (x' h, y', z'), h = 1 + kappa (e_Vy z - e_Vz y) (the centre's own radius against the centreline's), and its
    acceleration (F components) a = (x'' h + 2 kappa x' (e_Vy z' - e_Vz y'), y'' + kappa h x'^2 e_Vz,
    z'' - kappa h x'^2 e_Vy): Newton m a = F gives the centrifugal terms. Gravity is m g e_V (the cant's lateral
    component), and the axle load becomes the quasi-static load of the carried mass M_c = axle_load / g at the
    frame's speed V: M_c (g e_V - kappa V^2 e_n,horizontal) = M_c (0, g sin c - kappa V^2 cos c,
    g cos c + kappa V^2 sin c) (its centrifugal force balanced by the cant at the balancing speed, as the wheelset's
    own). Euler with the absolute angular velocity omega_a = omega + Omega (omega relative to F, from the Euler
    rates): J omega' = M - omega_a x J omega_a + J (omega x Omega) - J Omega', Omega' = kappa x'' e_V: the
    gyroscopic couple of the spin with the frame's yaw rate V/R is in omega_a x J omega_a. The suspension (in
    _assemble) acts between the wheelset and a frame that follows the track (relative positions and velocities), the
    yaw springs about the track's tangent.

    Energy: the kinetic energy and potential of the checks are those relative to F with gravity along b (T of the
    relative velocities, -m g z); the power of everything this function changes against the straight track (the
    frame's inertial terms, gravity's cant component, the carried mass's load) is added to ``p_ext``, so that
    d(T + V_g)/dt = P_contact + P_exterior holds as on straight track.
    """
    fe0, fe1, fe2 = fe
    me0, me1, me2 = me
    kap, s_, c_ = par.curvature_1_per_m, par.cant_sin, par.cant_cos
    g, m, speed = par.gravity_m_per_s2, par.mass_kg, par.speed_m_per_s
    yc, zc = y[Y], y[Z]
    vx, vy, vz = y[X_VELOCITY], y[Y_VELOCITY], y[Z_VELOCITY]
    h = 1.0 + kap * (s_ * zc - c_ * yc)
    mc = par.carried_mass_kg
    fs0 = force[0] + fe0
    fs1 = force[1] + fe1
    fs2 = force[2] + fe2 + m * g  # the straight track's forces (axle load along z, gravity along z)
    f0 = fs0
    f1 = force[1] + fe1 + mc * (g * s_ - kap * speed * speed * c_) + m * g * s_
    f2 = force[2] + fe2 - par.axle_load_N + mc * (g * c_ + kap * speed * speed * s_) + m * g * c_
    acc0 = (f0 / m - 2.0 * kap * vx * (s_ * vz - c_ * vy)) / h
    acc1 = f1 / m - kap * h * vx * vx * c_
    acc2 = f2 / m + kap * h * vx * vx * s_
    p_ext += m * (vx * acc0 + vy * acc1 + vz * acc2) - (vx * fs0 + vy * fs1 + vz * fs2)
    jb0, jb1, jb2 = par.inertia_transverse_kg_m2, par.inertia_axial_kg_m2, par.inertia_transverse_kg_m2
    w = kap * vx
    wd = kap * acc0
    o1, o2 = w * s_, w * c_  # Omega (its x component is 0)
    wa0, wa1, wa2 = om[0], om[1] + o1, om[2] + o2
    jw0, jw1, jw2 = _j_times(rzx, jb0, jb1, jb2, wa0, wa1, wa2)
    t0 = moment[0] + me0 - (wa1 * jw2 - wa2 * jw1)
    t1 = moment[1] + me1 - (wa2 * jw0 - wa0 * jw2)
    t2 = moment[2] + me2 - (wa0 * jw1 - wa1 * jw0)
    c0 = (rzx[0, 0] * t0 + rzx[1, 0] * t1 + rzx[2, 0] * t2) / jb0
    c1 = (rzx[0, 1] * t0 + rzx[1, 1] * t1 + rzx[2, 1] * t2) / jb1
    c2 = (rzx[0, 2] * t0 + rzx[1, 2] * t1 + rzx[2, 2] * t2) / jb2
    # + omega x Omega - Omega'
    al0 = rzx[0, 0] * c0 + rzx[0, 1] * c1 + rzx[0, 2] * c2 + (om[1] * o2 - om[2] * o1)
    al1 = rzx[1, 0] * c0 + rzx[1, 1] * c1 + rzx[1, 2] * c2 + (0.0 - om[0] * o2) - wd * s_
    al2 = rzx[2, 0] * c0 + rzx[2, 1] * c1 + rzx[2, 2] * c2 + (om[0] * o1 - 0.0) - wd * c_
    ja0, ja1, ja2 = _j_times(rzx, jb0, jb1, jb2, al0, al1, al2)
    p_ext += (
        om[0] * ja0
        + om[1] * ja1
        + om[2] * ja2
        - (om[0] * (moment[0] + me0) + om[1] * (moment[1] + me1) + om[2] * (moment[2] + me2))
    )
    return acc0, acc1, acc2, al0, al1, al2, p_ext


@njit(cache=True, _nrt=False)
def _assemble(t, y, par, force, moment, p_con, rail_force, om, rzx, out):
    """The equations of motion (eq 59-71 with the gyroscopic term), the suspension and the track: d/dt of the full
    state into ``out`` from the summed contact force and moment about the centre (main frame, N and N m), the
    contact power ``p_con`` (W), the contact forces on the rails ``rail_force`` = (vertical left, right, lateral
    left, right; elastic track) and the angular velocity ``om`` and rotation R_z R_x ``rzx`` of :func:`_rotation`.
    The one implementation: every right-hand side (the compiled loop and wheelset_model.WheelsetModel.derivative
    for scipy's methods) ends here through compiled_rhs._forces.
    """
    xc, yc, zc = y[X], y[Y], y[Z]
    yaw, roll = y[YAW], y[ROLL]
    vx, vy, vz = y[X_VELOCITY], y[Y_VELOCITY], y[Z_VELOCITY]
    yr, rr, sr = y[YAW_RATE], y[ROLL_RATE], y[SPIN_RATE]
    cps, sps, cth, sth = math.cos(yaw), math.sin(yaw), math.cos(roll), math.sin(roll)
    # exterior forces: axle load, primary suspension to the frame moving at the speed, yaw springs, torque
    fe0, fe1, fe2 = 0.0, 0.0, par.axle_load_N
    me0, me1, me2 = 0.0, 0.0, 0.0
    p_ext = par.axle_load_N * vz
    ax0, ax1, ax2 = -sps * cth, cps * cth, sth
    x_frame = par.frame_x0_m + par.speed_m_per_s * t
    # the frame's points, yawed by the held frame_yaw_rad (a bogie frame's angle to the track at this axle)
    frame_cos, frame_sin = math.cos(par.frame_yaw_rad), math.sin(par.frame_yaw_rad)
    for s in (-1.0, 1.0):
        sb_ = s * par.suspension_half_spacing_m
        a0, a1, a2 = ax0 * sb_, ax1 * sb_, ax2 * sb_
        v0 = vx + om[1] * a2 - om[2] * a1
        v1 = vy + om[2] * a0 - om[0] * a2
        v2 = vz + om[0] * a1 - om[1] * a0
        f0 = -par.suspension_kx_N_per_m * (xc + a0 - x_frame + frame_sin * sb_) - par.suspension_cx_N_s_per_m * (
            v0 - par.speed_m_per_s
        )
        f1 = -par.suspension_ky_N_per_m * (yc + a1 - frame_cos * sb_) - par.suspension_cy_N_s_per_m * (v1 - 0.0)
        f2 = -par.suspension_kz_N_per_m * (zc + a2 - par.frame_z_m) - par.suspension_cz_N_s_per_m * (v2 - 0.0)
        fe0 += f0
        fe1 += f1
        fe2 += f2
        me0 += a1 * f2 - a2 * f1
        me1 += a2 * f0 - a0 * f2
        me2 += a0 * f1 - a1 * f0
        p_ext += f0 * v0 + f1 * v1 + f2 * v2
    myaw = -2.0 * (par.yaw_stiffness_N_m_per_rad * (yaw - par.frame_yaw_rad) + par.yaw_damping_N_m_s_per_rad * yr)
    me2 += myaw
    p_ext += myaw * om[2]
    if par.torque_N_m != 0.0:
        mt0, mt1, mt2 = -par.torque_N_m * ax0, -par.torque_N_m * ax1, -par.torque_N_m * ax2
        me0 += mt0
        me1 += mt1
        me2 += mt2
        p_ext += mt0 * om[0] + mt1 * om[1] + mt2 * om[2]
    jb0, jb1, jb2 = par.inertia_transverse_kg_m2, par.inertia_axial_kg_m2, par.inertia_transverse_kg_m2
    if par.track_frame > 0:
        acc0, acc1, acc2, al0, al1, al2, p_ext = _assemble_curve(
            y, par, force, moment, (fe0, fe1, fe2), (me0, me1, me2), om, rzx, p_ext
        )
    else:
        acc0 = (force[0] + fe0) / par.mass_kg
        acc1 = (force[1] + fe1) / par.mass_kg
        acc2 = (force[2] + fe2) / par.mass_kg + par.gravity_m_per_s2
        # J = R J_body R^T with R = R_z R_x orthogonal: J omega and J^-1 torque = R J_body^-1 R^T torque (no solve)
        b0 = rzx[0, 0] * om[0] + rzx[1, 0] * om[1] + rzx[2, 0] * om[2]
        b1 = rzx[0, 1] * om[0] + rzx[1, 1] * om[1] + rzx[2, 1] * om[2]
        b2 = rzx[0, 2] * om[0] + rzx[1, 2] * om[1] + rzx[2, 2] * om[2]
        jw0 = rzx[0, 0] * jb0 * b0 + rzx[0, 1] * jb1 * b1 + rzx[0, 2] * jb2 * b2
        jw1 = rzx[1, 0] * jb0 * b0 + rzx[1, 1] * jb1 * b1 + rzx[1, 2] * jb2 * b2
        jw2 = rzx[2, 0] * jb0 * b0 + rzx[2, 1] * jb1 * b1 + rzx[2, 2] * jb2 * b2
        t0 = moment[0] + me0 - (om[1] * jw2 - om[2] * jw1)
        t1 = moment[1] + me1 - (om[2] * jw0 - om[0] * jw2)
        t2 = moment[2] + me2 - (om[0] * jw1 - om[1] * jw0)
        c0 = (rzx[0, 0] * t0 + rzx[1, 0] * t1 + rzx[2, 0] * t2) / jb0
        c1 = (rzx[0, 1] * t0 + rzx[1, 1] * t1 + rzx[2, 1] * t2) / jb1
        c2 = (rzx[0, 2] * t0 + rzx[1, 2] * t1 + rzx[2, 2] * t2) / jb2
        al0 = rzx[0, 0] * c0 + rzx[0, 1] * c1 + rzx[0, 2] * c2
        al1 = rzx[1, 0] * c0 + rzx[1, 1] * c1 + rzx[1, 2] * c2
        al2 = rzx[2, 0] * c0 + rzx[2, 1] * c1 + rzx[2, 2] * c2
    out[X], out[Y], out[Z] = vx, vy, vz
    out[YAW], out[ROLL], out[SPIN] = yr, rr, sr
    out[X_VELOCITY], out[Y_VELOCITY], out[Z_VELOCITY] = acc0, acc1, acc2
    out[YAW_RATE] = (al0 * sps * sth - al1 * cps * sth + al2 * cth + yr * rr * sth + rr * sr) / cth
    out[SPIN_RATE] = (al0 * sps - al1 * cps + yr * rr + rr * sr * sth) / cth
    out[ROLL_RATE] = al0 * cps + al1 * sps - yr * sr * cth
    if par.elastic_track > 0:
        rail_f0, rail_f1, rail_fy0, rail_fy1 = rail_force
        p_ext = _track_rates(par, y, rail_f0, rail_f1, rail_fy0, rail_fy1, out, p_ext)
    out[WORK_CONTACT], out[WORK_EXTERIOR] = p_con, p_ext


@njit(cache=True, _nrt=False)
def _rotation(y, om, rzx):
    """R_z(yaw) R_x(roll) into ``rzx`` (3, 3) and the angular velocity (main frame, eq 68-70) into ``om`` (3)."""
    yaw, roll = y[YAW], y[ROLL]
    yr, rr, sr = y[YAW_RATE], y[ROLL_RATE], y[SPIN_RATE]
    cps, sps, cth, sth = math.cos(yaw), math.sin(yaw), math.cos(roll), math.sin(roll)
    rzx[0, 0], rzx[0, 1], rzx[0, 2] = cps, -sps * cth, sps * sth
    rzx[1, 0], rzx[1, 1], rzx[1, 2] = sps, cps * cth, -cps * sth
    rzx[2, 0], rzx[2, 1], rzx[2, 2] = 0.0, sth, cth
    om[0], om[1], om[2] = rr * cps + sr * sps * cth, rr * sps - sr * cps * cth, yr - sr * sth


@njit(cache=True)
def track_rates(par, y, rail_force, out):
    """:func:`_track_rates` alone (full state ``y`` with the track; rates into ``out``) under ``rail_force``
    (vertical left, right[, lateral left, right]); returns the dampers' power.
    """
    lateral = rail_force.shape[0] > LATERAL_LEFT
    fy0, fy1 = (rail_force[LATERAL_LEFT], rail_force[LATERAL_RIGHT]) if lateral else (0.0, 0.0)
    return _track_rates(par, y, rail_force[VERTICAL_LEFT], rail_force[VERTICAL_RIGHT], fy0, fy1, out, 0.0)
