"""``report.md`` of ``tcsim design`` (docs/design.md, "tcsim design"): the design, what the design
model derives from it (with the formulas), the comparison with the reference converter (steady
state, isolated take-off, launch) and the figures, in one Markdown page beside the files."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from ..analysis.design_report import DesignReport
from ..models.design_file import DesignFile
from .format import fmt_number

#: The comparison rows: summary column, label with unit, format.
COMPARISON_ROWS: tuple[tuple[str, str, str], ...] = (
    ("stall_torque_ratio", "stall torque ratio [-]", ".4f"),
    ("stall_k_factor_rpm_per_sqrt_nm", "K-factor at stall, 2000 rpm [rpm/√(N·m)]", ".2f"),
    ("peak_converter_efficiency", "peak efficiency below the coupling point [-]", ".4f"),
    ("coupling_point_speed_ratio", "coupling point [SR]", ".4f"),
    ("takeoff_effective_tr_dip", "take-off: effective-TR dip below the steady state [-]", ".4f"),
    ("takeoff_effective_tr_dip_time_s", "take-off: time of the dip [s]", ".2f"),
    ("takeoff_effective_tr_recovery_time_s", "take-off: recovery within ±0.01 [s from 0.1 s]", ".3f"),
    ("takeoff_turbine_speed_1s_rad_s", "take-off: turbine speed at 1.1 s [rad/s]", ".2f"),
    ("launch_time_0_50_km_h_s", "launch: 0–50 km/h [s from the release]", ".3f"),
    ("launch_effective_tr_deficit_first_0_5_s", "launch: mean effective-TR deficit, first 0.5 s [-]", ".4f"),
    ("pump_shape_effect_m2", "S_p [m²]", ".6g"),
    ("turbine_shape_effect_m2", "S_t [m²]", ".6g"),
    ("stator_shape_effect_m2", "S_s [m²]", ".6g"),
)
#: The figures ``tcsim design`` writes, with captions.
FIGURES: tuple[tuple[str, str], ...] = (
    ("torque_ratio.png", "Torque ratio (Hrovat & Tobler closed form)"),
    ("capacity_factor.png", "Capacity factor"),
    ("efficiency.png", "Efficiency"),
    ("takeoff_effective_torque_ratio.png", "Isolated take-off: effective torque ratio"),
    ("takeoff_turbine_speed.png", "Isolated take-off: turbine speed"),
    ("launch_effective_torque_ratio.png", "Launch: effective torque ratio"),
    ("launch_vehicle_speed.png", "Launch: vehicle speed"),
)


def _design_rows(report: DesignReport) -> list[str]:
    """What the design model derives, per element, with the formulas."""
    g = report.derived.geometry
    inertia = report.derived.converter.inertia
    assert inertia is not None  # a derived converter has [inertia]
    lines = [
        "| element | S = R_exit·\\|tan α_exit\\|·L [m²] | axial extent L [mm] | fluid inertia ρA∫R²dl [kg·m²] "
        "| total inertia [kg·m²] | fluid mass [kg] |",
        "|---|---|---|---|---|---|",
    ]
    for name in ("pump", "turbine", "stator"):
        e = getattr(g, name)
        total = getattr(inertia, f"{name}_kg_m2")
        lines.append(
            f"| {name} | {e.shape_effect_m2:.6g} | {1e3 * e.axial_extent_m:.2f} | {e.fluid_inertia_kg_m2:.6g} "
            f"| {total:.6g} | {e.fluid_mass_kg:.4g} |"
        )
    lf = f"Equivalent fluid length L_f = Σ∫(1 + tan²α) dl = {g.fluid_length_m:.6g} m"
    lines += ["", f"{lf}; torus fluid mass {g.fluid_mass_kg:.4g} kg."]
    return lines


def _comparison_rows(summary: pd.DataFrame) -> list[str]:
    """The summary, one row per quantity, one column per converter."""
    names = [str(n) for n in summary["converter"]]
    roles = [str(r) for r in summary["role"]]
    lines = [
        "| quantity | " + " | ".join(f"{n} ({r})" for n, r in zip(names, roles)) + " |",
        "|---|" + "---|" * len(names),
    ]
    for column, label, spec in COMPARISON_ROWS:
        values = " | ".join(fmt_number(float(v), spec) for v in summary[column])
        lines.append(f"| {label} | {values} |")
    return lines


def _profile(file: DesignFile) -> str:
    d = file.design
    return f"elliptic, squash ratio {d.squash_ratio:g}" if d.profile == "elliptic" else d.profile


def report_markdown(report: DesignReport, file: DesignFile, files: set[str]) -> str:
    """``report.md`` for ``report`` of the design ``file``; ``files`` are the names written beside it
    (the figures among them are linked)."""
    lines = [
        f"# {report.derived.converter.name}: from the design to its behaviour",
        "",
        f"Design file `{Path(file.path).name}` ({_profile(file)} profile); reference converter "
        f"`{report.reference.name}`. Every value of `converter.toml` names its source in `[sources]` "
        "(docs/design.md).",
        "",
        "## Derived converter",
        "",
        *_design_rows(report),
        "",
        "Shape effects by Li & Sundén (2016) eqs 2.16–2.18 as §4.1.1 reads them (eqs 4.1–4.2), a magnitude "
        "as the thesis's chapter 4 uses it; a larger S deepens the effective-TR dip in transients.",
    ]
    if report.derived.default_losses:
        defaults = ", ".join(report.derived.default_losses)
        lines += ["", f"Loss coefficients from Table D.1 (not in the design): {defaults}."]
    lines += [
        "",
        "## Design against the reference (Hrovat & Tobler model)",
        "",
        *_comparison_rows(report.summary),
        "",
        "Take-off: pump torque 40 → 250 N·m over 0.1–0.3 s, turbine load 1.2 kg·m², 10 N·m + 0.002 N·m/(rad/s)². "
        "Launch: the bundled vehicle, flip-flop from a 1 s brake hold to 50 km/h. Deficits and dips are "
        "measured against each converter's own steady-state torque ratio at the same speed ratio.",
        "",
        "## Figures",
        "",
    ]
    for name, caption in FIGURES:
        if name in files:
            lines += [f"![{caption}]({name})", ""]
    return "\n".join(lines) + "\n"


__all__ = ["COMPARISON_ROWS", "FIGURES", "report_markdown"]
