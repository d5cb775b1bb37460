"""The Python half of the five-minute tour (docs/getting-started.md); tests/test_docs.py runs it."""

import dataclasses

import wheelrail as wr

# One Hertzian patch: a wheel of radius 0.46 m on a rail head of 0.3 m, steel, 100 kN, with creepage.
material = wr.STEEL
geometry = wr.ContactGeometry.quadric(0.46, 0.3)
creepage = wr.Creepage(1e-3, 0.0, 0.0)  # longitudinal, lateral (-), spin (1/m)
for name in ("linear", "vermeulen-johnson", "fastsim", "fastrip"):
    result = wr.get_model(name).solve(geometry, creepage, material, normal_force_N=1e5)
    print(
        f"{name:18s} {result.status:3s} Fx = {result.creep_force_long_N / 1e3:7.2f} kN  "
        f"p0 = {result.max_pressure_Pa / 1e6:6.0f} MPa  a x b = {result.semi_axis_long_m * 1e3:.2f} x "
        f"{result.semi_axis_lat_m * 1e3:.2f} mm"
    )

# An embedded contact case, as `wheelrail contact hertz-quadric --method hertz` solves it.
case = wr.load_case("hertz-quadric")
solution = wr.solve_case(case, "hertz")
print(solution)

# A dynamics scene, shortened: a conical wheelset hunting on straight track (`wheelrail run hunting-conical`).
scene = wr.load_scene("hunting-conical")
run = wr.simulate(dataclasses.replace(scene, duration_s=0.2))
print(run.status, run.message)
table = run.to_dataframe()  # one row per output time, units in the column names
print(table[["time_s", "y_m"]].tail(3))
