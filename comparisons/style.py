"""One look for every figure: a colour and a marker per rung, errors in %, pressures and stresses in MPa.

The same rung has the same colour in the bench's per-case plots and overview, the comparison maps and the
dynamics plots, so a reader can follow a rung from one figure to the next.
"""

from __future__ import annotations

RUNG_COLOURS = {
    "hertz": "#7f7f7f",
    "linear": "#1f77b4",
    "vermeulen-johnson": "#17becf",
    "fastsim": "#2ca02c",
    "fastrip": "#bcbd22",
    "kpec": "#9467bd",
    "bem": "#d62728",
    "fea": "#ff7f0e",
    "auto": "#8c564b",
    "reference": "#000000",
}
RUNG_MARKERS = {
    "hertz": "s",
    "linear": "v",
    "vermeulen-johnson": "^",
    "fastsim": "o",
    "fastrip": "P",
    "kpec": "X",
    "bem": "D",
    "fea": "*",
    "auto": "h",
    "reference": "x",
}


def rung_style(model: str) -> dict:
    """Matplotlib keyword arguments (colour, marker, label) of a rung; unknown names get black circles."""
    return {"color": RUNG_COLOURS.get(model, "k"), "marker": RUNG_MARKERS.get(model, "o"), "label": model}


def percent_axis(axis) -> None:
    """Label a log axis of fractions in % (0.01 -> "1 %") without overlapping minor labels."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    axis.set_major_locator(LogLocator(base=10))
    axis.set_major_formatter(FuncFormatter(lambda v, _: f"{100 * v:g} %"))
    axis.set_minor_formatter(NullFormatter())


def seconds_axis(axis, low: float, high: float) -> None:
    """Label a log axis of times in plain numbers ("0.001", "0.3"): majors only over a wide range, and 2 and 5 of
    each decade as well where the range is under 1.5 decades (matplotlib's default labels every minor tick there,
    and they overlap in a small panel).
    """
    import math

    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    if high > 0 and low > 0 and math.log10(high / low) < 1.5:
        axis.set_minor_locator(LogLocator(base=10, subs=(2.0, 5.0)))
        axis.set_minor_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    else:
        axis.set_minor_formatter(NullFormatter())


_UNIT_SUFFIXES = (
    ("_m_per_s", "m/s"), ("_1_per_m", "1/m"), ("_N_per_m", "N/m"), ("_Pa", "Pa"), ("_Nm", "N m"), ("_N", "N"),
    ("_m2", "m^2"), ("_rad", "rad"), ("_kg", "kg"), ("_Hz", "Hz"), ("_m", "m"), ("_s", "s"),
)  # fmt: skip
_READABLE = {"m": ("mm", 1e3), "Pa": ("MPa", 1e-6), "m^2": ("mm^2", 1e6), "rad": ("mrad", 1e3)}
_NAMES = {
    "energy_balance_relative": "relative energy residual",
    "max_force_ratio": "largest normal force / static load",
}


def unit_of(name: str) -> str:
    """The SI unit a name's suffix states (``slip_m_per_s`` -> "m/s", ``pressure_Pa`` -> "Pa"); "1" for none."""
    for suffix, unit in _UNIT_SUFFIXES:
        if name.endswith(suffix):
            return unit
    return "1"


def label_of(name: str) -> tuple[str, float]:
    """An axis label for a column name and the factor that converts its values: ``y_amplitude_m`` ->
    ("y amplitude [mm]", 1e3); metres, pascals and radians in the units a railway engineer reads (mm, MPa, mrad).
    """
    if name in _NAMES:
        return _NAMES[name], 1.0
    if "." in name:  # a dotted scene key: its last part names the quantity
        name = name.rsplit(".", 1)[-1]
    unit = unit_of(name)
    stem = name
    if unit != "1":
        suffix = next(sfx for sfx, u in _UNIT_SUFFIXES if u == unit and name.endswith(sfx))
        stem = name[: -len(suffix)]
    shown, scale = _READABLE.get(unit, (unit, 1.0))
    text = stem.replace("_", " ").strip()
    return (f"{text} [{shown}]" if unit != "1" else text), scale
