"""``vfem export``, ``vfem reference`` and ``vfem plot``: the commands that solve nothing."""

from __future__ import annotations

import sys
from pathlib import Path

from ..errors import InputError
from .builtin import example_configs, export_header


def cmd_export(args) -> int:
    from ..io.input import dumps

    configs = example_configs(args.example, args.set or [])
    header = export_header(args.example, args.set or [])
    if len(configs) == 1 and not args.out:
        print(dumps(next(iter(configs.values())), header), end="")
        return 0
    if not args.out:
        raise InputError(f"the {args.example} example has {len(configs)} models; give --out "
                         "DIR to write one file each")
    out = Path(args.out)
    if len(configs) == 1:
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(dumps(next(iter(configs.values())), header), encoding="utf-8")
        written = [out]
    else:
        out.mkdir(parents=True, exist_ok=True)
        written = []
        for key, config in configs.items():
            path = out / f"{key}.toml"
            path.write_text(dumps(config, header + f"\nThis file: {config.name}."),
                            encoding="utf-8")
            written.append(path)
    if not args.quiet:
        print(f"vfem: wrote {', '.join(str(p) for p in written)}")
    return 0


def cmd_reference(args) -> int:
    from ..io.input import reference

    print(reference(), end="")
    return 0


def cmd_plot(args) -> int:
    from ..io.replot import plot_results, unfinished_example

    why = unfinished_example(Path(args.results))  # an example's own figures cannot be drawn
    if why and not args.quiet:
        print(f"vfem: {why}", file=sys.stderr)
    notes: list[str] = []  # what was not drawn, and why (a 3D body with no node in contact)
    written = plot_results(Path(args.results), notes)
    if not args.quiet:
        print(f"vfem: wrote {', '.join(str(p) for p in written)}" if written else
              f"vfem: {args.results}: no figures to draw (its run drew none)")
        for note in notes:
            print(f"vfem: not drawn: {note}", file=sys.stderr)
    return 0
