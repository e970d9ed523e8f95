"""Parameters of the Laser/ILCA velocity-prediction program (VPP).

:class:`LaserParams` holds every number the VPP in :mod:`sailroute.boat.vpp`
uses, in SI units with unit-suffixed names.  Three class sets are provided:
:data:`ILCA7` (standard rig), :data:`ILCA6` (radial) and :data:`ILCA4` (4.7).
The same dataclass also describes a keelboat (``stability="heel"``, a jib),
which the YD-41 structure check in the tests uses.

Sources (``docs/vpp.md`` has the full discussion):

* [T] the Laser minimal-time-path thesis (TU Delft, 2018), §2 and §4.2-4.3.1:
  boat 59 kg, LOA 4.2 m, beam 1.37 m, sail 7.06 / 5.76 m², CE 2.68 m, board
  0.23 m², rudder 0.11 m², draft 0.787 m, ρa 1.225, C_twist 8.0, C_Ds 0.005,
  windage Cd 1.075 / 0.954 with areas reduced 20 %, hull drag area 0.025 m².
* [ILCA] class rules and builder data: ILCA 4 sail 4.70 m², LWL 3.81 m.
* [ORC] ORC VPP sail coefficient tables as shipped by Python-VPP (MIT):
  ``data/main.dat``, ``data/jib.dat``; flattening lowers the CE by
  0.203 (1 - flat) of its height (ORC VPP documentation, Python-VPP
  ``AeroMod._vce``); effective-span factor 1.1.
* [DSYHS] Delft Systematic Yacht Hull Series residuary resistance regression
  (Keuning & Sonnenberg 1998, coefficients from Fossati, *Aero-hydrodynamics
  and the performance of sailing yachts*, table 2.5), ``data/wr.dat``.
* [A] assumption of this project, stated where it is made.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, fields, replace
from typing import Any, Final

from sailroute.checks import Checker, Problems, join_path, quoted, show, split_where, suggest
from sailroute.errors import InputError

HULL_MODELS: Final = ("dsyhs", "thesis")
STABILITY_MODELS: Final = ("hiking", "heel")
CREW_MASS_RANGE_KG: Final = (20.0, 200.0)
"""Accepted sailor mass of a hiking dinghy [kg] (``stability="hiking"``)."""


@dataclass(frozen=True)
class LaserParams:
    """All inputs of the VPP, SI units.

    Attributes are grouped below; each states its source ([T] thesis, [ILCA],
    [ORC], [DSYHS], [A] assumption; see the module docstring).
    """

    name: str = "ILCA 7"
    """Label of the boat."""

    # --- masses ---------------------------------------------------------------
    hull_mass_kg: float = 59.0
    """Boat (hull + rig) mass [kg] [T]."""
    crew_mass_kg: float = 80.0
    """Sailor mass [kg].  [A]: typical ILCA 7 racing weight; the thesis used
    70 kg (top of its 55-70 kg range)."""

    # --- hull -----------------------------------------------------------------
    loa_m: float = 4.2
    """Length overall [m] [T]."""
    beam_m: float = 1.37
    """Maximum beam [m] [T]; half of it is the thesis's Y_max (eq 2.31)."""
    lwl_m: float = 3.81
    """Waterline length [m] [ILCA]."""
    bwl_m: float = 1.10
    """Waterline beam [m] [A]: estimate for a 139 kg displacement."""
    prismatic_coefficient: float = 0.56
    """Cp [A] (planing-dinghy value, inside the DSYHS range 0.52-0.60)."""
    midship_coefficient: float = 0.70
    """Cm [A]; with Cp it fixes the canoe-body draft Tc = ∇ / (Cp Cm Bwl Lwl)."""
    waterplane_coefficient: float = 0.72
    """Cw = Aw / (Lwl Bwl) [A]."""
    lcb_fraction: float = 0.54
    """LCB from the forward perpendicular, fraction of Lwl [A]."""
    lcf_fraction: float = 0.57
    """LCF from the forward perpendicular, fraction of Lwl [A]."""
    wetted_area_m2: float = 0.0
    """Hull wetted area [m²]; 0 means 1.08 Aw (a shallow, flat hull wets
    slightly more than its waterplane) [A]."""
    form_factor: float = 0.05
    """Hull form factor k: viscous resistance = (1 + k) x ITTC-57 friction [A]."""
    hull_model: str = "dsyhs"
    """``"dsyhs"``: ITTC-57 friction + DSYHS residuary resistance (default);
    ``"thesis"``: the thesis's single drag area, R = ½ ρw V² x
    :attr:`hull_drag_area_m2` (eq 4.19)."""
    hull_drag_area_m2: float = 0.025
    """Thesis hull drag-area coefficient [m²] (eq 4.19), used by ``hull_model="thesis"``."""

    # --- appendages ---------------------------------------------------------
    board_area_m2: float = 0.23
    """Daggerboard area [m²] [T]."""
    rudder_area_m2: float = 0.11
    """Rudder area [m²] [T]."""
    appendage_chord_m: float = 0.30
    """Mean chord of board and rudder for their friction Reynolds number [m] [A]."""
    appendage_form_factor: float = 0.20
    """Form factor of the foils (t/c ≈ 10 %) [A] (Python-VPP uses 1.21 for its rudder)."""
    max_draft_m: float = 0.787
    """Draft of the board tip below the waterline [m] [T, 'T_c']."""
    effective_draft_m: float = 0.0
    """Effective span for induced drag [m]; 0 means :attr:`max_draft_m` [A].
    Induced resistance = F_side² / (½ ρw V² π T_eff²) (Python-VPP form)."""
    clr_depth_m: float = 0.35
    """Depth of the centre of lateral resistance below the waterline [m] [A];
    the heeling arm is CE height + this."""

    # --- rig (mainsail) -------------------------------------------------------
    sail_area_m2: float = 7.06
    """Mainsail area [m²] [T]."""
    ce_height_m: float = 2.68
    """Height of the centre of effort above the water [m] [T]."""
    sail_foot_height_m: float = 0.60
    """Height of the boom/sail foot above the water [m] [A]; the thesis puts
    the CE at foot + 40 % of the sail height, so sail height =
    (CE - foot) / 0.4."""
    effective_span_m: float = 0.0
    """Effective rig height for induced drag [m]; 0 means 1.1 x the sail
    height [ORC factor]."""

    # --- jib (keelboats only; 0 for the Laser) --------------------------------
    jib_area_m2: float = 0.0
    """Jib area [m²]; its ORC coefficients are area-weighted with the main's."""
    jib_ce_height_m: float = 0.0
    """Jib centre of effort above the water [m]."""
    kite_area_m2: float = 0.0
    """Spinnaker area [m²] (keelboats only); the VPP also solves main + kite
    (ORC kite table) and keeps the faster sail set at each point."""
    kite_ce_height_m: float = 0.0
    """Spinnaker centre of effort above the water [m]."""
    headsail_table: str = "jib"
    """ORC table of the second sail: ``"jib"`` or ``"kite"`` (set internally
    when the main + kite set is solved)."""

    # --- sail model (thesis eq 4.4 on ORC tables) ----------------------------
    c_twist: float = 8.0
    """Twist penalty C_twist on the induced drag (1 + C_twist t²) [T]."""
    c_ds: float = 0.005
    """Quadratic parasitic drag C_Ds (multiplies f² C_L²) [T]."""
    c_dp: float = 0.0
    """Constant parasitic drag C_Dp [A]: 0, because mast drag is part of the
    ORC table and hull/crew windage is modelled separately."""
    twist_ce_drop: float = 0.15
    """Full twist (t = 1) lowers the CE by this fraction of its height above
    the foot [A]: the head unloads."""
    flat_ce_drop: float = 0.203
    """Flattening lowers the CE by this x (1 - flat) [ORC]."""
    flat_min: float = 0.0
    """Lowest flat [-] (0: the sail can be eased until it luffs)."""
    ease_flat: float = 0.6
    """Below this flat the sail is eased rather than flattened [A] (0.6 is about
    the ORC VPP's lowest flat): its viscous drag falls linearly from C_Dv(β) to
    the luffing value C_Dv(0) at flat 0.  0 disables easing."""
    twist_max: float = 1.0
    """Highest twist t [-] [T: t ∈ [0, 1]]; 0 disables twist."""

    # --- windage (thesis eq 4.5) -----------------------------------------------
    windage_cd_front: float = 1.075
    """Drag coefficient of hull + crew head-on [T]."""
    windage_cd_side: float = 0.954
    """Drag coefficient of hull + crew beam-on [T]."""
    windage_area_front_m2: float = 0.50
    """Frontal area of hull + hiking crew before the 20 % shielding [m²] [A]."""
    windage_area_side_m2: float = 1.20
    """Side area of hull + crew before the 20 % shielding [m²] [A]."""
    windage_shielding: float = 0.20
    """Area reduction for shielding by the cockpit [T]."""

    # --- stability ----------------------------------------------------------
    stability: str = "hiking"
    """``"hiking"``: boat sailed flat, the crew's position y_c ∈ [-1, 1]
    balances the heeling moment, depowering when fully hiked;
    ``"heel"``: keelboat, heel from the righting-arm curve."""
    hiking_extension_m: float = 0.45
    """Crew centre of mass outboard of the gunwale when fully hiked [m] [A]:
    thighs on the deck edge, torso out; the hiking arm is beam/2 + this."""
    gz_heel_deg: tuple[float, ...] = (0.0, 10.0, 20.0, 30.0, 40.0)
    """Heel angles of the righting-arm curve [°] (``stability="heel"``)."""
    gz_m: tuple[float, ...] = (0.0, 0.0, 0.0, 0.0, 0.0)
    """Righting arm GZ of the whole boat at :attr:`gz_heel_deg` [m]."""
    crew_arm_m: float = 0.0
    """Crew righting arm on the rail for ``stability="heel"`` [m]."""
    max_heel_deg: float = 0.0
    """Largest heel the keelboat is sailed at [°]; beyond it the sails are
    flattened; 0 means the last angle of :attr:`gz_heel_deg`."""

    # --- environment ---------------------------------------------------------
    rho_air: float = 1.225
    """Air density [kg m⁻³] [T]."""
    rho_water: float = 1025.0
    """Water density [kg m⁻³]: sea water; the thesis printed 1000 [A]."""
    nu_water: float = 1.19e-6
    """Kinematic viscosity of sea water at 15 °C [m² s⁻¹] (ITTC)."""
    gravity: float = 9.81
    """[m s⁻²]."""

    # --- derived quantities ---------------------------------------------------------

    @property
    def displacement_kg(self) -> float:
        """Total mass (boat + crew) [kg]."""
        return self.hull_mass_kg + self.crew_mass_kg

    @property
    def volume_m3(self) -> float:
        """Displaced volume ∇ [m³]."""
        return self.displacement_kg / self.rho_water

    @property
    def canoe_draft_m(self) -> float:
        """Canoe-body draft Tc = ∇ / (Cp Cm Bwl Lwl) [m]."""
        return self.volume_m3 / (
            self.prismatic_coefficient * self.midship_coefficient * self.bwl_m * self.lwl_m
        )

    @property
    def waterplane_area_m2(self) -> float:
        """Waterplane area Aw = Cw Lwl Bwl [m²]."""
        return self.waterplane_coefficient * self.lwl_m * self.bwl_m

    @property
    def hull_wetted_area_m2(self) -> float:
        """Hull wetted area [m²] (:attr:`wetted_area_m2` or 1.08 Aw)."""
        return self.wetted_area_m2 or 1.08 * self.waterplane_area_m2

    @property
    def sail_height_m(self) -> float:
        """Sail height (CE - foot) / 0.4 [m]."""
        return (self.ce_height_m - self.sail_foot_height_m) / 0.4

    @property
    def span_m(self) -> float:
        """Effective rig height for induced drag [m]."""
        return self.effective_span_m or 1.1 * self.sail_height_m

    @property
    def aspect_ratio(self) -> float:
        """Effective aspect ratio AR_E = span² / total sail area [-]."""
        return self.span_m**2 / (self.sail_area_m2 + self.jib_area_m2)

    @property
    def hiking_arm_m(self) -> float:
        """Crew righting arm when fully hiked, beam/2 + extension [m]."""
        return 0.5 * self.beam_m + self.hiking_extension_m

    @property
    def max_righting_moment_nm(self) -> float:
        """Largest crew righting moment, boat flat [N m]."""
        return self.crew_mass_kg * self.gravity * self.hiking_arm_m


def _smaller_rig(
    base: LaserParams, name: str, sail_area_m2: float, crew_mass_kg: float
) -> LaserParams:
    """``base`` with a smaller mainsail [m²] and another sailor [kg].

    The foot height stays and the sail height scales with √area (shorter lower
    mast) [A]; the CE stays at 40 % of the sail height, so its height above the
    foot scales with √area too.
    """
    foot = base.sail_foot_height_m
    ce = foot + (base.ce_height_m - foot) * (sail_area_m2 / base.sail_area_m2) ** 0.5
    return replace(
        base, name=name, sail_area_m2=sail_area_m2, ce_height_m=ce, crew_mass_kg=crew_mass_kg
    )


ILCA7: Final = LaserParams()
"""ILCA 7 (standard rig, 7.06 m²), 80 kg sailor."""

ILCA6: Final = _smaller_rig(ILCA7, "ILCA 6", sail_area_m2=5.76, crew_mass_kg=68.0)
"""ILCA 6 (radial, 5.76 m² [T]); the sail height scales with √area
(shorter lower mast, same foot height) [A]; 68 kg sailor [A]."""

ILCA4: Final = _smaller_rig(ILCA7, "ILCA 4", sail_area_m2=4.70, crew_mass_kg=58.0)
"""ILCA 4 (4.7 rig, 4.70 m² [ILCA]); sail height scaled with √area [A];
58 kg sailor [A]."""

CLASSES: Final[dict[str, LaserParams]] = {"ilca4": ILCA4, "ilca6": ILCA6, "ilca7": ILCA7}
"""Parameter sets by class name."""

_RESERVED: Final = ("class",)


def param_names() -> tuple[str, ...]:
    """Names of the overridable parameters (the dataclass fields)."""
    return tuple(f.name for f in fields(LaserParams))


def params_from_mapping(
    spec: Any, *, where: str, key: str = "", lines: Mapping[str, int] | None = None
) -> LaserParams:
    """Build parameters from a mapping ``{class: ilca7, crew_mass_kg: 75, ...}``.

    Parameters
    ----------
    spec : mapping
        ``class`` (``ilca4``, ``ilca6``, ``ilca7``; default ``ilca7``) and any
        :class:`LaserParams` field as an override.
    where : str
        File label for messages (e.g. ``"boats/me.yaml"``), or ``"file:LINE"`` of
        the block (the line of problems whose own line is not in ``lines``).
    key : str
        Key path of ``spec`` inside the file (e.g. ``"boat.vpp"``), prefixed
        to each problem.
    lines : mapping of str to int, optional
        1-based line of each key of ``spec`` in the file; a problem about a key
        with a known line is reported as ``where:LINE: key: ...``.

    Raises
    ------
    InputError
        Listing every problem (unknown key, with a "did you mean" where one is
        close; bad class; wrong type; bad value) with its key path, in the wording
        of :mod:`sailroute.checks`.
    """
    file, line, _ = split_where(where)
    known = {join_path(key, str(k)): v for k, v in (lines or {}).items()}
    if line is not None:  # ``where`` is "file:LINE" of the block: the fallback line
        known.setdefault("", line)
    probs = Problems(file, known, what="boat spec" if key else "boat file")
    if not isinstance(spec, dict):
        raise InputError(
            f"{where}: {key or 'boat'}: expected a mapping of parameters; got {show(spec)}"
        )
    params = check_params(Checker(probs, key), spec)
    probs.raise_if_any()
    assert params is not None
    return params


def check_params(c: Checker, spec: Any) -> LaserParams | None:
    """Build parameters from the mapping at ``c.path``, recording problems in ``c``.

    The checker-level form of :func:`params_from_mapping`: a course's ``boat.vpp``
    block is checked with the rest of its ``boat:`` block, its problems collected
    with theirs (:func:`sailroute.boat.build.boat_from_spec`).

    Parameters
    ----------
    c : Checker
        Checker of the block's key path (``"boat.vpp"``; ``""`` for a boat file).
    spec : Any
        The parsed block: ``class`` and :class:`LaserParams` fields as overrides.

    Returns
    -------
    LaserParams or None
        None after a problem (type and value checks first; the cross-field checks
        of :func:`validate` only on a parameter set that passed them).
    """
    if not isinstance(spec, Mapping):
        c.add(None, f"expected a mapping of parameters; got {show(spec)}")
        return None
    before = len(c.p)
    cls = spec.get("class", "ilca7")
    base = ILCA7
    if not isinstance(cls, str) or cls.lower() not in CLASSES:
        hint = suggest(cls.lower(), CLASSES).strip() if isinstance(cls, str) else ""
        c.add(
            "class",
            f"expected one of {quoted(sorted(CLASSES))}; got {show(cls)}"
            + (f" ({hint})" if hint else ""),
        )
    else:
        base = CLASSES[cls.lower()]
    names = [f.name for f in fields(LaserParams)]
    overrides: dict[str, Any] = {}
    for k, v in spec.items():
        if k in _RESERVED:
            continue
        if k not in names:
            # "weight" is what sailors say for mass (crew_weight -> crew_mass_kg)
            word = str(k).lower().replace("weight", "mass")
            c.add(
                str(k),
                f"unknown key; {suggest(word, [*_RESERVED, *names])}expected "
                "'class' or a parameter such as 'crew_mass_kg' (see docs/vpp.md for the "
                "full list)",
            )
            continue
        default = getattr(base, k)
        if isinstance(default, str):
            v = c.string(spec, k)
        elif isinstance(default, tuple):
            if not isinstance(v, list | tuple) or not all(
                isinstance(x, int | float) and not isinstance(x, bool) for x in v
            ):
                c.add(k, f"expected a list of numbers; got {v!r}")
                continue
            v = tuple(float(x) for x in v)
        else:
            v = c.number(spec, k)
        if v is not None:
            overrides[k] = v
    if len(c.p) > before:
        return None
    params = replace(base, **overrides)
    for problem in validate(params):
        name, message = problem.split(": ", 1)
        c.add(name, message)
    return params if len(c.p) == before else None


def validate(p: LaserParams) -> list[str]:
    """Problems with a parameter set (empty if it is usable), each naming its field."""
    return [*_number_problems(p), *_model_problems(p), *_sail_crew_problems(p)]


def _number_problems(p: LaserParams) -> list[str]:
    """Fields that must be finite and positive, non-negative or in [0, 1]; the sail's
    centre of effort above its foot."""
    out: list[str] = []
    positive = (
        "hull_mass_kg",
        "crew_mass_kg",
        "loa_m",
        "beam_m",
        "lwl_m",
        "bwl_m",
        "prismatic_coefficient",
        "midship_coefficient",
        "waterplane_coefficient",
        "lcb_fraction",
        "lcf_fraction",
        "board_area_m2",
        "appendage_chord_m",
        "max_draft_m",
        "sail_area_m2",
        "ce_height_m",
        "rho_air",
        "rho_water",
        "nu_water",
        "gravity",
        "hull_drag_area_m2",
    )
    for name in positive:
        v = getattr(p, name)
        if not v > 0 or v != v or v == float("inf"):
            out.append(f"{name}: expected a finite number > 0; got {v!r}")
    nonneg = (
        "wetted_area_m2",
        "form_factor",
        "rudder_area_m2",
        "appendage_form_factor",
        "effective_draft_m",
        "clr_depth_m",
        "sail_foot_height_m",
        "effective_span_m",
        "jib_area_m2",
        "jib_ce_height_m",
        "c_twist",
        "c_ds",
        "c_dp",
        "twist_ce_drop",
        "flat_ce_drop",
        "flat_min",
        "ease_flat",
        "twist_max",
        "windage_cd_front",
        "windage_cd_side",
        "windage_area_front_m2",
        "windage_area_side_m2",
        "windage_shielding",
        "hiking_extension_m",
        "crew_arm_m",
        "kite_area_m2",
        "kite_ce_height_m",
        "max_heel_deg",
    )
    for name in nonneg:
        v = getattr(p, name)
        if not v >= 0 or v == float("inf"):
            out.append(f"{name}: expected a finite number >= 0; got {v!r}")
    if not 0 <= p.flat_min < 1:
        out.append(f"flat_min: expected a number in [0, 1); got {p.flat_min!r}")
    if not 0 <= p.ease_flat <= 1:
        out.append(f"ease_flat: expected a number in [0, 1]; got {p.ease_flat!r}")
    if not 0 <= p.twist_max <= 1:
        out.append(f"twist_max: expected a number in [0, 1]; got {p.twist_max!r}")
    if not 0 <= p.windage_shielding < 1:
        out.append(f"windage_shielding: expected a number in [0, 1); got {p.windage_shielding!r}")
    if p.ce_height_m <= p.sail_foot_height_m:
        out.append(
            f"ce_height_m: must be above sail_foot_height_m ({p.sail_foot_height_m}); "
            f"got {p.ce_height_m}"
        )
    return out


def _model_problems(p: LaserParams) -> list[str]:
    """Hull and stability models known; a righting-arm curve of increasing heel."""
    out: list[str] = []
    if p.hull_model not in HULL_MODELS:
        out.append(
            f"hull_model: expected one of {', '.join(map(repr, HULL_MODELS))}; got {p.hull_model!r}"
        )
    if p.stability not in STABILITY_MODELS:
        out.append(
            f"stability: expected one of {', '.join(map(repr, STABILITY_MODELS))}; "
            f"got {p.stability!r}"
        )
    if len(p.gz_heel_deg) != len(p.gz_m) or len(p.gz_m) < 2:
        out.append("gz_heel_deg, gz_m: need two lists of the same length (at least 2)")
    elif any(b <= a for a, b in zip(p.gz_heel_deg, p.gz_heel_deg[1:], strict=False)):
        out.append("gz_heel_deg: must increase strictly")
    return out


def _sail_crew_problems(p: LaserParams) -> list[str]:
    """Heights of the headsails' centres of effort, the headsail table, the crew mass of a
    hiking dinghy and some stability with ``stability: heel``."""
    out: list[str] = []
    if p.jib_area_m2 > 0 and p.jib_ce_height_m <= 0:
        out.append("jib_ce_height_m: must be > 0 when jib_area_m2 > 0")
    if p.kite_area_m2 > 0 and p.kite_ce_height_m <= 0:
        out.append("kite_ce_height_m: must be > 0 when kite_area_m2 > 0")
    if p.headsail_table not in ("jib", "kite"):
        out.append(f"headsail_table: expected 'jib' or 'kite'; got {p.headsail_table!r}")
    lo, hi = CREW_MASS_RANGE_KG
    if p.stability == "hiking" and p.crew_mass_kg > 0 and not lo <= p.crew_mass_kg <= hi:
        out.append(
            f"crew_mass_kg: expected a sailor mass in {lo:g}-{hi:g} kg for a hiking "
            f"dinghy; got {p.crew_mass_kg!r}"
        )
    if p.stability == "heel" and not (max(p.gz_m, default=0.0) > 0 or p.crew_arm_m > 0):
        out.append(
            "gz_m: stability 'heel' needs a righting-arm curve with a positive value "
            "(or crew_arm_m > 0); with none the boat cannot carry sail. Give gz_m "
            "(and gz_heel_deg) or use stability: hiking"
        )
    return out


__all__ = [
    "CLASSES",
    "CREW_MASS_RANGE_KG",
    "ILCA4",
    "ILCA6",
    "ILCA7",
    "LaserParams",
    "check_params",
    "param_names",
    "params_from_mapping",
    "validate",
]
