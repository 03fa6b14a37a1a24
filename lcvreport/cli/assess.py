"""``lcv assess``: every measure of a scheme file at its own conditions, judged per level; the
verdict table, the level each measure reaches and the vehicle's (docs/assessment.md)."""
from __future__ import annotations

from .options import Command, UsageError, add_load, add_source, add_tire_scale, case_of, help_range, one_line
from .output import Output


def load_scheme_option(path: str):
    """The scheme of ``--scheme`` (one line naming the key, exit 2, before anything is computed)."""
    from ..measures.scheme import SchemeError, load_scheme
    try:
        return load_scheme(path)
    except SchemeError as exc:
        raise UsageError(f"argument --scheme {path}: {exc}") from None


def _file_bytes(path: str, what: str) -> bytes:
    """The bytes of a file the command has read and checked already (its digest for the JSON)."""
    from ..util.files import FileInputError, read_file_bytes
    try:
        return read_file_bytes(path, what)
    except FileInputError as exc:
        raise UsageError(f"argument {exc}") from None


def assessment_of(args):
    """(vehicle, scheme, assessment) of the options; the assessment names the files it read
    (their names and SHA-256)."""
    from pathlib import Path

    from ..model.presets import preset_path
    case = case_of(args, speed=False)       # the scheme gives each measure's speed and conditions
    v = case.vehicle
    scheme = load_scheme_option(args.scheme)
    a = case.assess(scheme)
    vehicle = (Path(args.vehicle).name, _file_bytes(args.vehicle, "vehicle file")) if args.vehicle is not None \
        else (f"preset {args.preset}", preset_path(args.preset).read_bytes())
    return v, scheme, a.with_files(vehicle, (Path(args.scheme).name, _file_bytes(args.scheme, "scheme file")))


def cmd_assess(args, out: Output) -> int:
    if args.out is not None:
        from ..report.publish import OutputFolderError, check_output_folder
        try:
            check_output_folder(args.out)          # before anything is computed
        except OutputFolderError as exc:
            raise UsageError(f"argument {exc}") from None
    v, scheme, a = assessment_of(args)
    # the verdict first: a report interrupted or failing after it leaves the verdict said
    if args.json:
        out.json(a.to_dict())
    else:
        for line in verdict_lines(a):
            out.line(line)
    out.flush()
    if args.out is not None:
        _write_report(args, a)
    return 0


def _write_report(args, a) -> None:
    """The assessment report into ``--out`` (docs/assessment.md#report)."""
    import sys

    from ..report.build import build_scheme_report
    from .artifacts import run_report
    text = None
    if args.vehicle is not None:               # the user's file as written, comments and all
        from ..model.vehicle_file import read_vehicle_text
        text = read_vehicle_text(args.vehicle)
    src = a.sources
    residuals = {"P_N": src.loads.P_N, "T_Nm": src.loads.T_Nm, "misalignment_rad": src.misalignment_rad} \
        if src else None
    run_report("lcv assess", lambda: build_scheme_report(
        a.vehicle, args.scheme, args.out, a.tire_scale, a.load_units or None, residuals, pdf=not args.no_pdf,
        paper=args.paper, source=a.files["vehicle"]["name"], vehicle_text=text,
        progress=lambda line: print(f"lcv assess: {line}", file=sys.stderr, flush=True)),
        lambda line: print(f"lcv assess: {line}", file=sys.stderr))


def verdict_lines(a) -> list[str]:
    """The verdict table as text lines: a header naming the scheme and its status, one line per
    measure (conditions, value, the verdict at every level, the level reached), the vehicle's
    level, and the reason of every measure that does not reach the first level."""
    from ..measures.assess import VERDICT_WORDS
    s = a.scheme
    status = {"template": " -- a TEMPLATE: its numbers are placeholders, not a standard",
              "draft": " -- a DRAFT"}.get(s.status, "")
    lines = [f"{a.vehicle.name} assessed against {one_line(s.name)}{status}",
             f"  levels, most demanding first: {', '.join(s.levels)}; tire scale {a.tire_scale:g}"]
    width = max(8, *(len(level) for level in s.levels))
    vw = max(10, *(len(m.value_text()) for m in a.measures))
    head = f"  {'measure':<28} {'conditions':<32} {'value':>{vw}} {'unit':<5}"
    lines.append(head + "".join(f" {level:>{width}}" for level in s.levels) + "  reached")
    for m in a.measures:
        row = f"  {m.key:<28} {m.conditions_text():<32} {m.value_text():>{vw}} {m.unit:<5}"
        lines.append(row + "".join(f" {VERDICT_WORDS[m.verdicts[level]]:>{width}}" for level in s.levels)
                     + f"  {m.level_reached or 'none'}")
    lines.append(f"  level reached by the vehicle: {a.level_reached or 'none'}"
                 + (f" ({one_line(a.reason)})" if a.reason else ""))
    from ..measures.registry import MEASURES
    for m in a.measures:
        if m.reason:
            lines.append(f"  {m.key}: {one_line(m.reason)}")
    for m in a.measures:
        if MEASURES[m.key].caveat:
            lines.append(f"  {m.key}: {MEASURES[m.key].caveat}")
    lines.append("  (n/c: not computed, the reason above; limits, margins and sources: lcv assess --json, or the "
                 "report)")
    return lines


def assess_options(sp) -> None:
    add_source(sp)
    sp.add_argument("--scheme", required=True, metavar="FILE",
                    help="the scheme file (TOML): levels, and per measure its conditions and limits per level, "
                         "each with its source (examples/schemes/)")
    add_tire_scale(sp)
    add_load(sp, False, convention=False)
    sp.add_argument("--residual", action="append", default=[], metavar="AXLE=P,T",
                    help="residual force P [N] (+y) and moment T [N*m] (+z) on an axle, a source of the trim and "
                         "the straight path; repeatable (the crossfall is the scheme's crossfall_percent)")
    sp.add_argument("--misalignment", action="append", default=[], metavar="AXLE=RAD",
                    help=f"thrust angle of an axle [rad], in {help_range('misalignment')}; repeatable or "
                         f"comma-separated")
    sp.add_argument("--tires", metavar="FILE", help="mounted tires (CSV or TOML): their axle P and T")
    sp.add_argument("--out", metavar="DIR", help="also write the assessment report (HTML, PDF; the verdict table "
                                                 "first, then the evidence of every measure): new, empty or an "
                                                 "earlier report")
    sp.add_argument("--no-pdf", action="store_true", help="with --out: HTML only")
    sp.add_argument("--paper", default="letter", choices=("letter", "a4"), help="paper of the PDF (default letter)")
    sp.add_argument("--json", action="store_true", help="machine-readable output (docs/assessment.md)")


COMMANDS = {"assess": Command("a performance-based standards assessment: every measure of a scheme file at its own "
                              "conditions, judged per level (docs/assessment.md)", assess_options, cmd_assess)}
