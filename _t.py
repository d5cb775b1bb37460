import dataclasses, time
from wheelrail.cases import load_case, solve_case
case = load_case("manchester-a22")
for y in (0.0, 0.002, 0.004):
  for incl in (0.0, 0.025):
    ws = dataclasses.replace(case.wheelset, wheel_profile="worn_high_mileage", rail_profile="site_b_hr", lateral_shift_m=y, yaw_rad=0.0, rail_inclination_rad=incl)
    c = dataclasses.replace(case, wheelset=ws)
    t=time.perf_counter(); s = solve_case(c, "hertz")
    print(y, incl, s.success, s.message[:50], f"{time.perf_counter()-t:.2f}", [(side, round(g.contact_angle_rad,3), round(r.normal_force_N), g.is_elliptic, round(r.max_pressure_Pa/1e6)) for side,g,cr,r in s.patches])
