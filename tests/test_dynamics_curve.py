"""Curves and cant (scene ``[track] curve_direction``, ``curve_radius_m``, ``cant_m``): verification.

Steady curving against an independent quasi-static solution. A suspended wheelset (primary longitudinal and
lateral springs to a bogie frame that follows the track) with conical wheels on circular rail heads and Kalker's
linear creep law runs through a right curve with cant until it settles (compiled RK4 on contact-geometry tables).
Its lateral position, yaw angle, normal loads and creep forces are compared with the quasi-static curving
solution computed here from the textbook model of a wheelset in a curve, not from the project's equations of
motion: the wheelset of Wickens (Fundamentals of Rail Vehicle Dynamics, 2003, ch. 2 and 6) and Garg & Dukkipati
(Dynamics of Railway Vehicle Systems, 1984, ch. 4 and 9; Iwnicki, Handbook of Railway Vehicle Dynamics, 2006, sets
it out the same way): the contact geometry of a cone on a circular rail head (the contact normal is the cone's,
turned by the wheelset's roll; the rail contact is the head's point of that normal; the roll and height follow from
both wheels touching), Kalker's creepages from the contact points' slip velocities with the wheelset's absolute
angular velocity (spin plus the curve's yaw rate V/R: the e0/R term of the longitudinal creepages and the 1/R
spin), Kalker's linear creep forces f_ij = G (ab)^k C_ij with the semi-axes from Hertz at each wheel's own load,
and the steady balance: the forces on the wheelset equal m times the centripetal acceleration, the moments equal
Omega x (J omega_a) (steady precession: the gyroscopic couple J_a (V/r0)(V/R) of the spin with the curve's yaw
rate), with gravity along the true vertical of the canted track and the carried mass's quasi-static load at the
axle (the model of compiled_motion._assemble_curve: the axle load is axle_load/g times g minus the centripetal
acceleration). The unknowns (y, psi, spin rate, the two normal loads, roll and centre height) are solved by
Newton's method (scipy.optimize.fsolve). Hertz (contact.hertz) and Kalker's table (contact.kalker)
are the project's own, verified elsewhere (tests/test_hertz.py, tests/test_kalker.py).

The two-equation textbook form of the same model (equal loads, no spin, no contact-angle terms; Wickens ch. 6) is
checked against it as well: within 1.5 % (y) and 2.5 % (psi) here.

Also: a left curve mirrors a right one; at the speed at which the cant balances the centrifugal force (zero cant
deficiency) the wheelset carries no net lateral load; bad curve and cant keys are one-line errors.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from rigid_dynamics.materials import STANDARD_GRAVITY_M_PER_S2 as G_STD
from rigid_dynamics.wheelset.parameters import (
    DynamicsScene,
    InitialConditions,
    IntegratorSettings,
    LoadParameters,
    SuspensionParameters,
    TrackGeometry,
    WheelsetParameters,
)
from rigid_dynamics.wheelset.simulate import simulate

R_CURVE = 400.0
CANT_M = 0.05
SPEED = 20.0
LAMBDA = 0.05
RAIL_RADIUS = 0.05
KX = KY = 5.0e6
B_S = 1.0
DURATION = 3.0


def curve_scene(direction="right", radius=R_CURVE, cant=CANT_M, speed=SPEED, **track):
    """The verification wheelset: Manchester wheelset, conical wheels (0.05) on 50 mm rail heads, primary springs."""
    return DynamicsScene(
        name="curve-check",
        wheelset=WheelsetParameters(),
        suspension=SuspensionParameters(
            longitudinal_stiffness_N_per_m=KX,
            lateral_stiffness_N_per_m=KY,
            longitudinal_damping_N_s_per_m=2.0e4,
            lateral_damping_N_s_per_m=2.0e4,
            vertical_damping_N_s_per_m=2.0e4,
        ),
        loads=LoadParameters(axle_load_N=160.0e3),
        track=TrackGeometry(
            wheel_profile="conical",
            rail_profile="circular",
            conicity=LAMBDA,
            rail_head_radius_m=RAIL_RADIUS,
            curve_direction=direction,
            curve_radius_m=radius if direction != "straight" else 0.0,
            cant_m=cant,
            **track,
        ),
        speed_m_per_s=speed,
        duration_s=DURATION,
        contact_model="linear",
        contact_provider="tables",
        settling_distance_m=0.0,
        integrator=IntegratorSettings(method="RK4", fixed_step_s=5e-4, output_step_s=0.01),
        initial=InitialConditions(),
    )


def quasi_static(scene: DynamicsScene, elastic: bool = False):
    """The independent steady curving solution (module docstring): dict of y, psi, per-wheel (left, right) normal
    loads N, contact-frame creep forces Tx, Ty and the creepages, all from the textbook model written here.

    ``elastic``: on the scene's elastic track at rest (``track_dynamics``: static springs only, the rails at rest in
    a steady state): each rail lowered by w = F_z / k_v and moved by u = F_y / k_y, F the force of its wheel on it
    (k_v the vertical pad and ballast in series, k_y the lateral stiffness; 0 for a rigid lateral track); w and u
    join the unknowns (returned as "rail_vertical", "rail_lateral", left and right).
    """
    from scipy.optimize import fsolve

    from rigid_dynamics.contact.hertz import hertz_solve_batch
    from rigid_dynamics.contact.kalker import kalker_coefficients

    ws, tr, mat = scene.wheelset, scene.track, scene.material
    m, jt, ja = ws.mass_kg, ws.transverse_inertia_kg_m2, ws.axle_inertia_kg_m2
    r0, e0, b = ws.nominal_radius_m, ws.contact_half_distance_m, ws.suspension_half_spacing_m
    kx, ky = scene.suspension.longitudinal_stiffness_N_per_m, scene.suspension.lateral_stiffness_N_per_m
    kyaw = scene.suspension.yaw_stiffness_N_m_per_rad
    g, v = G_STD, scene.speed_m_per_s
    mc = scene.loads.axle_load_N / g
    kappa = tr.curvature_1_per_m
    phi = tr.cant_rad
    s, c = math.sin(phi), math.cos(phi)
    lam = tr.conicity
    delta0 = math.atan(lam)
    gmod, nu = mat.shear_modulus_Pa, mat.poisson_ratio
    omega_frame = kappa * v * np.array([0.0, s, c])  # the track frame's angular velocity (about the true vertical)
    j_body = np.diag([jt, ja, jt])

    track = scene.track_dynamics
    k_v = track.static_stiffness_N_per_m if elastic else 0.0
    k_y = track.lateral_rail_stiffness_N_per_m if elastic and track.lateral else 0.0

    def wheel_state(x):
        y, psi, spin, n_l, n_r, theta, z_c = x[:7]
        rail_w = x[7:9] if elastic else np.zeros(2)
        rail_u = x[9:11] if elastic else np.zeros(2)
        rot = np.array(
            [
                [math.cos(psi), -math.sin(psi) * math.cos(theta), math.sin(psi) * math.sin(theta)],
                [math.sin(psi), math.cos(psi) * math.cos(theta), -math.cos(psi) * math.sin(theta)],
                [0.0, math.sin(theta), math.cos(theta)],
            ]
        )
        axle = rot[:, 1]
        omega_a = -spin * axle + omega_frame  # absolute angular velocity (spin about -axle: forward rolling)
        h = 1.0 + kappa * (s * z_c - c * y)
        v_c = np.array([v * h, 0.0, 0.0])  # the centre's absolute velocity (its circle's radius R - y_h)
        geometry = []
        force = np.zeros(3)
        moment = np.zeros(3)
        rows = []
        track_residual = []
        for side, (sign, load) in enumerate(((-1.0, n_l), (1.0, n_r))):
            # cone R(y_d) = r0 + lambda (e0 - sign y_d) on a circular head: the normal is the cone's, turned by the
            # roll; the rail contact is where the head's slope equals it (the head's point of that normal)
            delta = delta0 + (theta if sign < 0 else -theta)
            normal = np.array([0.0, -sign * math.sin(delta), -math.cos(delta)])  # rail into wheel
            rail_y = sign * (e0 + tr.rail_head_radius_m * math.sin(delta0)) + tr.rail_head_radius_m * normal[1]
            rail_z = tr.rail_head_radius_m * (math.cos(delta0) + normal[2])
            rail_y, rail_z = rail_y + rail_u[side], rail_z + rail_w[side]  # the rail moved by its track (z down)
            y_d = sign * e0
            for _ in range(4):  # the wheel's point above it (lever = y_d axle + R(y_d) x perpendicular, lowest line)
                radius = r0 + lam * (e0 - sign * y_d)
                y_d = (rail_y - y + radius * math.sin(theta)) / math.cos(theta)
            radius = r0 + lam * (e0 - sign * y_d)
            lever = np.array([-math.sin(psi) * y_d, rail_y - y, y_d * math.sin(theta) + radius * math.cos(theta)])
            geometry.append(z_c + lever[2] - rail_z)  # the wheel touches the rail (rigid profiles, as the tables)
            slip = v_c + np.cross(omega_a, lever)  # the rail is at rest
            e_x = np.array([1.0, 0.0, 0.0])  # rolling direction (the track's), in the contact plane: n_x = 0
            e_y = np.cross(normal, e_x)
            speed = v * h
            xi, eta, sp = slip @ e_x / speed, slip @ e_y / speed, omega_a @ normal / speed
            hz = hertz_solve_batch(
                np.array([0.5 / (radius * math.sqrt(1 + lam * lam))]),
                np.array([0.5 / tr.rail_head_radius_m]),
                normal_force_N=np.array([load]),
                shear_modulus_Pa=gmod,
                poisson_ratio=nu,
            )
            a, bb = float(hz.semi_axis_long_m[0]), float(hz.semi_axis_lat_m[0])
            cc = kalker_coefficients(np.array([a / bb]), nu)
            ab = a * bb
            tx = -gmod * ab * float(cc.c11[0]) * xi
            ty = -gmod * ab * float(cc.c22[0]) * eta - gmod * ab**1.5 * float(cc.c23[0]) * sp
            mz = gmod * ab**1.5 * float(cc.c23[0]) * eta - gmod * ab**2 * float(cc.c33[0]) * sp
            f = tx * e_x + ty * e_y + load * normal
            if elastic:  # the rail at rest on its springs under -f, the force of the wheel on it
                track_residual += [(k_v * rail_w[side] + f[2]) / 1e3]
                track_residual += [(k_y * rail_u[side] + f[1]) / 1e3 if k_y > 0 else rail_u[side] * 1e3]
            force += f
            moment += np.cross(lever, f) + mz * normal
            rows.append((load, tx, ty, xi, eta, sp))
        # primary springs to the frame following the track (longitudinal offset: the springs' sum balances the
        # longitudinal creep forces and adds no moment by symmetry; it is left out), yaw springs
        for sign in (-1.0, 1.0):
            attach = sign * b * axle
            f_s = np.array([-kx * attach[0], -ky * (y + attach[1] - sign * b), 0.0])
            force += f_s
            moment += np.cross(attach, f_s)
        moment[2] += -2.0 * kyaw * psi
        # gravity along the true vertical of the canted track, the carried mass's quasi-static load at the axle
        force += m * g * np.array([0.0, s, c]) + mc * np.array(
            [0.0, g * s - kappa * v * v * c, g * c + kappa * v * v * s]
        )
        # steady state: m a = F with the centripetal acceleration; dH/dt = Omega x H = M
        accel = kappa * h * v * v * np.array([0.0, c, -s])
        precession = np.cross(omega_frame, rot @ j_body @ rot.T @ omega_a)
        residual = np.concatenate(
            [(force - m * accel)[1:] / 1e3, (moment - precession) / 1e3, np.array(geometry) * 1e3,
             np.array(track_residual)]
        )  # fmt: skip
        return residual, rows

    def equations(x):
        res, _ = wheel_state(x)
        return res  # y-force, z-force, roll, spin, yaw, the two wheels' contact

    w0 = 0.5 * (m * g + scene.loads.axle_load_N)
    x0 = np.array([-0.003, -0.002, v / r0, w0, w0, 0.0, -r0] + ([0.0] * 4 if elastic else []))
    x, info, ok, msg = fsolve(equations, x0, full_output=True, xtol=1e-13)
    assert ok == 1, msg
    res, rows = wheel_state(x)
    assert np.max(np.abs(res)) < 1e-6
    rows = np.array(rows)
    return {
        "rail_vertical": x[7:9] if elastic else np.zeros(2),
        "rail_lateral": x[9:11] if elastic else np.zeros(2),
        "y": x[0],
        "psi": x[1],
        "N": rows[:, 0],
        "Tx": rows[:, 1],
        "Ty": rows[:, 2],
        "xi": rows[:, 3],
        "eta": rows[:, 4],
        "spin": rows[:, 5],
    }


def settled(result):
    """Last sample's y, psi and per-wheel (tread slot) N, Tx, Ty, creepages; the change over the last 0.5 s."""
    p = result.patches
    k = -1
    out = {
        "y": result.states[k, 1],
        "psi": result.states[k, 3],
        "roll": result.states[k, 4],
        "N": p["normal_force_N"][k, :, 0],
        "Tx": p["creep_force_long_N"][k, :, 0],
        "Ty": p["creep_force_lat_N"][k, :, 0],
        "xi": p["creepage_long"][k, :, 0],
        "eta": p["creepage_lat"][k, :, 0],
        "spin": p["spin_creepage_1_per_m"][k, :, 0],
    }
    back = int(round(0.5 / (result.t[1] - result.t[0])))
    drift = abs(result.states[k, 1] - result.states[k - back, 1])
    return out, drift


@pytest.fixture(scope="module")
def right_curve():
    scene = curve_scene()
    result = simulate(scene)
    assert result.status == "ok", result.message
    assert result.compiled
    return scene, result


def test_steady_curving_against_the_quasi_static_solution(right_curve):
    scene, result = right_curve
    sim, drift = settled(result)
    ref = quasi_static(scene)
    assert drift < 1e-7  # settled
    # measured: y -5.482 mm, psi -1.9469 mrad against -5.485 mm, -1.9479 mrad (0.05 %); N 75.86 / 102.47 kN against
    # 75.85 / 102.48 kN; Tx -13.10 / 13.03 kN, Ty 22.33 / 19.09 kN against -13.11 / 13.04, 22.34 / 19.11 kN (0.07 %)
    assert sim["y"] == pytest.approx(ref["y"], rel=0.005)
    assert sim["psi"] == pytest.approx(ref["psi"], rel=0.005)
    assert sim["N"] == pytest.approx(ref["N"], rel=1e-3)
    for key in ("Tx", "Ty", "xi", "eta"):
        assert np.max(np.abs(sim[key] - ref[key])) < 0.005 * np.max(np.abs(ref[key])), key
    assert sim["spin"] == pytest.approx(ref["spin"], rel=1e-4)
    # the gyroscopic couple J_a (V/r0)(V/R) of the spin with the curve's yaw rate moves N_left - N_right by
    # J_a V^2 / (R r0 e0) = 325 N; the load difference agrees to far less (measured 17 N)
    gyro = scene.wheelset.axle_inertia_kg_m2 * SPEED**2 / (R_CURVE * 0.46 * 0.75)
    assert abs((sim["N"][0] - sim["N"][1]) - (ref["N"][0] - ref["N"][1])) < 0.2 * gyro
    # the outer wheel (left in a right curve) is the one behind the pure-rolling line: outward shift, nose out
    assert sim["y"] < 0 and sim["psi"] < 0


def test_quasi_static_solution_against_the_two_equation_textbook_form():
    """The two-equation linear model (Wickens 2003, ch. 6; Garg & Dukkipati 1984, ch. 9): yaw k_psi psi = -2 f11 e0
    (e0/R + lambda_e y / r0), lateral 2 f22 psi - k_y y - F_u = 0 with F_u = (m + M_c)(V^2/R cos c - g sin c) the
    unbalanced force (outwards, -y), equal loads, no spin, no contact-angle terms: y -5.570 mm, psi -1.997 mrad
    against the full quasi-static solution's -5.485 mm, -1.948 mrad (1.5 %, 2.5 %: the terms it leaves out)."""
    from rigid_dynamics.contact.hertz import hertz_solve_batch
    from rigid_dynamics.contact.kalker import kalker_coefficients

    scene = curve_scene()
    ws, tr = scene.wheelset, scene.track
    w0 = scene.static_wheel_load_N
    hz = hertz_solve_batch(
        np.array([0.5 / ws.nominal_radius_m]), np.array([0.5 / RAIL_RADIUS]), normal_force_N=np.array([w0]),
        shear_modulus_Pa=scene.material.shear_modulus_Pa, poisson_ratio=scene.material.poisson_ratio,
    )  # fmt: skip
    a, b = float(hz.semi_axis_long_m[0]), float(hz.semi_axis_lat_m[0])
    cc = kalker_coefficients(np.array([a / b]), scene.material.poisson_ratio)
    f11 = scene.material.shear_modulus_Pa * a * b * float(cc.c11[0])
    f22 = scene.material.shear_modulus_Pa * a * b * float(cc.c22[0])
    e0, r0 = ws.contact_half_distance_m, ws.nominal_radius_m
    lam_e = LAMBDA / (1 - LAMBDA * RAIL_RADIUS / e0)  # effective conicity of a cone on a rail head of radius R_r
    k_psi = 2 * KX * B_S**2
    k_y = 2 * KY
    mass = ws.mass_kg + scene.loads.axle_load_N / G_STD
    unbalanced = mass * (SPEED**2 / R_CURVE * math.cos(tr.cant_rad) - G_STD * math.sin(tr.cant_rad))
    # unknowns (y, psi): 2 f11 e0 lambda_e / r0 y + k_psi psi = -2 f11 e0^2 / R; -k_y y + 2 f22 psi = unbalanced
    mat = np.array([[2 * f11 * e0 * lam_e / r0, k_psi], [-k_y, 2 * f22]])
    rhs = np.array([-2 * f11 * e0 * e0 / R_CURVE, unbalanced])
    y, psi = np.linalg.solve(mat, rhs)
    ref = quasi_static(scene)
    assert y == pytest.approx(ref["y"], rel=0.03)
    assert psi == pytest.approx(ref["psi"], rel=0.04)


def test_left_curve_mirrors_the_right_one(right_curve):
    _, right = right_curve
    left = simulate(curve_scene("left"))
    assert left.status == "ok", left.message
    r, _ = settled(right)
    lf, _ = settled(left)
    assert lf["y"] == pytest.approx(-r["y"], rel=1e-6)
    assert lf["psi"] == pytest.approx(-r["psi"], rel=1e-6)
    assert lf["roll"] == pytest.approx(-r["roll"], rel=1e-5, abs=1e-12)
    assert lf["N"] == pytest.approx(r["N"][::-1], rel=1e-8)
    assert lf["Tx"] == pytest.approx(r["Tx"][::-1], rel=1e-6)
    # the contact frame's e_y = n x e_x points to the left on both wheels: lateral forces change sign
    assert lf["Ty"] == pytest.approx(-r["Ty"][::-1], rel=1e-6)
    fr, fl = right.contact_force_N[-1], left.contact_force_N[-1]
    assert fl[:, 0] == pytest.approx(fr[::-1, 0], rel=1e-6)
    assert fl[:, 1] == pytest.approx(-fr[::-1, 1], rel=1e-6)


def test_zero_cant_deficiency_leaves_no_net_lateral_load(right_curve):
    """At the balancing speed V^2 = g R tan(cant) the lateral components of gravity and of the centrifugal force
    cancel for the wheelset and its carried mass: the rails' lateral forces and the suspension's balance each other
    (the wheelset carries no net lateral load); at the test's 20 m/s they carry the unbalanced force."""
    scene, deficient = right_curve
    phi = scene.track.cant_rad
    balancing = math.sqrt(G_STD * R_CURVE * math.tan(phi))
    # EN 13803's deficiency w V^2/(g R) - D uses tan = sin: 0.03 mm at the exact balance
    assert scene.track.cant_deficiency_m(balancing, G_STD) == pytest.approx(0.0, abs=1e-4)
    balanced = simulate(curve_scene(speed=balancing))
    assert balanced.status == "ok", balanced.message
    mass = scene.wheelset.mass_kg + scene.loads.axle_load_N / G_STD

    def net_lateral(result):
        y = result.states[-1, 1]
        contact = float(np.sum(result.contact_force_N[-1, :, 1]))
        return contact - 2 * KY * y  # the lateral springs (their yaw terms are second order)

    unbalanced = mass * (SPEED**2 / R_CURVE * math.cos(phi) - G_STD * math.sin(phi))
    assert net_lateral(deficient) == pytest.approx(unbalanced, rel=0.01)  # the rails and springs carry it
    # balanced: the residue is the wheelset centre's own smaller radius (h = 1 - (r0 sin c + y cos c)/R), ~1e-4
    assert abs(net_lateral(balanced)) < 1e-3 * unbalanced
    ref = quasi_static(curve_scene(speed=balancing))
    assert balanced.states[-1, 1] == pytest.approx(ref["y"], rel=0.01)
    assert balanced.states[-1, 3] == pytest.approx(ref["psi"], rel=0.01)


def test_python_path_matches_the_compiled_one_in_a_curve():
    """The Python right-hand side takes the same frame terms (creepages with the absolute velocities)."""
    scene = replace(curve_scene(), duration_s=0.2)
    compiled = simulate(scene)
    python = simulate(scene, compiled=False)
    assert compiled.compiled and not python.compiled
    scale = np.max(np.abs(compiled.states[:, 1]))
    assert np.max(np.abs(compiled.states[:, 1] - python.states[:, 1])) < 1e-9 * max(scale, 1e-3)
    assert np.max(np.abs(compiled.states[:, 3] - python.states[:, 3])) < 1e-9


def test_energy_balance_holds_in_a_curve(right_curve):
    _, result = right_curve
    assert result.summary()["energy_balance_relative"] < 1e-6


def _settled_scene(name):
    """An embedded scene as shipped (settled at its end: curve within 4 s of its 6 s, curve-flange within 1 s)."""
    from wheelrail.scenes import load_scene

    return load_scene(name)


def test_curve_scenes_tread_and_flange():
    """Regression of the embedded scenes' steady state (the numbers their files quote): curve (600 m, tables) stays
    on the tread near the pure-rolling line, curve-flange (100 m, the 3-D search) runs on the outer wheel's flange
    root (against the exact profile section within 0.045 mm: tests/test_search_flange.py)."""
    tread = simulate(_settled_scene("curve"))
    flange = simulate(_settled_scene("curve-flange"))
    # energy balance: 2e-10 on the tables (curve); 5.2e-6 on the 3-D search of curve-flange, whose tracked contact
    # points and tabulated surface curvatures make the normal force a slightly non-conservative field
    for result, bound in ((tread, 1e-6), (flange, 1e-5)):
        assert result.status == "ok", result.message
        assert result.summary()["energy_balance_relative"] < bound
    angle = tread.patches["contact_angle_rad"][-1, 0, 0]
    assert tread.states[-1, 1] == pytest.approx(-3.861e-3, rel=2e-3) and angle < 0.2
    assert abs(tread.patches["creepage_long"][-1, 0, 0]) < 1e-4
    assert not any(kind == "flange-contact" for kind, _, _ in tread.events)
    angle = flange.patches["contact_angle_rad"][-1, 0, 0]
    assert flange.states[-1, 1] == pytest.approx(-6.279e-3, rel=2e-3)
    assert angle > flange.scene.track.flange_contact_angle_rad
    assert any(kind == "flange-contact" and side == "left" for kind, side, _ in flange.events)
    curve = flange.summary()["curve"]
    assert curve["cant_deficiency_m"] == pytest.approx(0.1451, abs=1e-4)
    assert tread.summary()["curve"]["cant_deficiency_m"] == pytest.approx(0.0967, abs=1e-4)


@pytest.mark.parametrize(
    ("old", "new", "pattern"),
    [
        ("curve_radius_m = 600.0", "curve_radius_m = -600.0", r"curve_radius_m = -600\.0: expected a radius >= 50"),
        ("curve_radius_m = 600.0", "curve_radius_m = 0.0", r"curve_radius_m = 0\.0: expected a radius >= 50"),
        ('curve_direction = "right"', 'curve_direction = "up"', r"curve_direction = 'up': expected one of"),
        ("cant_m = 0.1", "cant_m = 0.5", r"cant_m' = 0\.5: expected a number from 0 to 0\.2"),
        ("cant_m = 0.1", "cant_m = -0.1", r"cant_m' = -0\.1: expected a number from 0 to 0\.2"),
        (
            'curve_direction = "right"\ncurve_radius_m = 600.0',
            'curve_direction = "straight"',
            r"cant_m = 0\.1: expected 0 on straight track",
        ),
        (
            'rail_profile = "UIC60"',
            'rail_profile = "UIC60"\nleft_rail_profile = "no_such_rail.prr"',
            r"key 'track\.left_rail_profile' = 'no_such_rail\.prr'",
        ),
        (
            'wheel_profile = "S1002"',
            'wheel_profile = "S1002"\nright_wheel_profile = "no_such_wheel.prw"',
            r"key 'track\.right_wheel_profile' = 'no_such_wheel\.prw'",
        ),
        (
            "rail_inclination_rad = 0.025",
            "rail_inclination_rad = 0.025\nleft_rail_inclination_rad = 0.5",
            r"left_rail_inclination_rad' = 0\.5: expected a number from -0\.2 to 0\.2",
        ),
    ],
)
def test_bad_curve_keys_are_one_line_errors(tmp_path, capsys, old, new, pattern):
    from hardening_helpers import assert_bad_scene

    assert_bad_scene(tmp_path, capsys, "curve", old, new, pattern)


def _straight_profiles(duration_s=0.3, **track):
    """polygonal-wheel without its polygon on a straight track, with per-side profile keys."""
    from rigid_dynamics.wheelset.parameters import Irregularities
    from wheelrail.scenes import load_scene

    scene = load_scene("polygonal-wheel")
    return replace(
        scene,
        duration_s=duration_s,
        irregularities=Irregularities(),
        track=replace(scene.track, **track),
        initial=replace(scene.initial, lateral_displacement_m=0.0),
        settling_distance_m=0.0,
    )


def test_per_side_keys_equal_to_the_shorthand_change_nothing():
    """Regression: naming the two-sided profiles and inclination per side gives the same run, bit for bit."""
    short = simulate(_straight_profiles())
    named = simulate(
        _straight_profiles(
            left_wheel_profile="S1002",
            right_wheel_profile="S1002",
            left_rail_profile="UIC60",
            right_rail_profile="UIC60",
            left_rail_inclination_rad=0.025,
            right_rail_inclination_rad=0.025,
        )
    )
    assert short.status == named.status == "ok"
    assert np.array_equal(short.states, named.states)


def test_swapped_sides_give_mirrored_results():
    """Unequal rails (left 1:20, right 1:40 inclination; left analytic UIC60, right the Manchester benchmark's UIC60
    file) and unequal wheels (left analytic S1002, right the benchmark's S1002 file) against the same with the sides
    swapped: the wheelset settles off-centre, and the swapped run is its mirror image."""
    sides = {
        "left_rail_inclination_rad": 0.05,
        "right_rail_inclination_rad": 0.025,
        "left_rail_profile": "UIC60",
        "right_rail_profile": "MBench_UIC60_v3",
        "left_wheel_profile": "S1002",
        "right_wheel_profile": "MBench_S1002_v3",
    }
    swapped = {k.replace("left", "@").replace("right", "left").replace("@", "right"): v for k, v in sides.items()}
    one = simulate(_straight_profiles(duration_s=1.0, **sides))
    two = simulate(_straight_profiles(duration_s=1.0, **swapped))
    assert one.status == "ok" and two.status == "ok", (one.message, two.message)
    y1, y2 = one.states[-1, 1], two.states[-1, 1]
    assert abs(y1) > 1e-5  # the asymmetric track moves the wheelset off-centre
    assert y2 == pytest.approx(-y1, rel=1e-4)
    assert two.states[-1, 3] == pytest.approx(-one.states[-1, 3], rel=1e-3, abs=1e-9)
    assert two.states[-1, 4] == pytest.approx(-one.states[-1, 4], rel=1e-4)
    n1, n2 = one.patches["normal_force_N"][-1, :, 0], two.patches["normal_force_N"][-1, :, 0]
    assert n2 == pytest.approx(n1[::-1], rel=1e-5)
    f1, f2 = one.contact_force_N[-1], two.contact_force_N[-1]
    assert f2[:, 1] == pytest.approx(-f1[::-1, 1], rel=1e-3, abs=1.0)


def test_critical_speed_refuses_a_curve(tmp_path, capsys):
    """critical-speed analyses the straight track's centred state: a curve scene is bad input, not a silent answer."""
    from hardening_helpers import assert_error, run

    out = tmp_path / "out"
    code, _, err = run(capsys, "critical-speed", "curve", "--out", out)
    assert_error(code, err, "track.curve_direction", "straight track")
    assert not out.exists()


def test_embedded_flange_curve_mirrors():
    """S1002/UIC60 on the flange root: the left-hand curve-flange is the mirror image of the right-hand one. On the
    scene's 3-D search (each wheel searched on its own profile, no sampled section), over its 2 s: measured y 5e-12,
    yaw 2e-9, normal loads 2e-10, lateral forces 5e-11 relative (after 1 s, still settling: 2e-7, 3e-5, 8e-5, 8e-5).
    On the profile tables (each wheel's section sampled from its own profile range's left end, so the two sides'
    samples are not mirror images) it mirrored to y 9e-5, yaw 1.2e-3, normal loads 2e-6, lateral forces 2.5e-4."""
    from wheelrail.scenes import load_scene

    scene = load_scene("curve-flange")
    assert scene.contact_provider == "search" and scene.duration_s == 2.0
    right = simulate(scene)
    left = simulate(replace(scene, track=replace(scene.track, curve_direction="left")))
    assert right.status == left.status == "ok"
    assert left.states[-1, 1] == pytest.approx(-right.states[-1, 1], rel=1e-8)
    assert left.states[-1, 3] == pytest.approx(-right.states[-1, 3], rel=1e-6)
    normal = right.patches["normal_force_N"][-1, ::-1, 0]
    assert left.patches["normal_force_N"][-1, :, 0] == pytest.approx(normal, rel=1e-7)
    assert left.contact_force_N[-1, :, 1] == pytest.approx(-right.contact_force_N[-1, ::-1, 1], rel=1e-7)
