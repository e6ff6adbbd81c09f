"""`thermofriction presets`: the shipped presets, listed or shown as model files (docs/cli.md#presets)."""

from __future__ import annotations

import sys
import tomllib

from ..errors import InputError, shorten
from ..models.model import PRESETS, preset_hint, preset_path


def preset_description(name: str) -> str:
    """The preset file's own ``description``."""
    return tomllib.loads(preset_path(name).read_text()).get("description", "")


def add_presets_command(sub):
    p = sub.add_parser("presets", help="list the shipped presets, or show one as a model file",
                       description="Without arguments: every preset, with its description. "
                                   "'presets show NAME': the preset's model file (TOML), to copy and edit.")
    actions = p.add_subparsers(dest="presets_action", metavar="ACTION")
    s = actions.add_parser("show", help="print a preset's model file (TOML)")
    s.add_argument("name", metavar="NAME", help="a preset name")
    p.set_defaults(run=cmd_presets)


def cmd_presets(args) -> int:
    if getattr(args, "presets_action", None) == "show":
        if args.name not in PRESETS:
            raise InputError(f"unknown preset {shorten(args.name)}{preset_hint(args.name)}")
        sys.stdout.write(preset_path(args.name).read_text())
        return 0
    width = max(map(len, PRESETS))
    for name in PRESETS:
        desc = " ".join(preset_description(name).split())
        first = desc.split(": ", 1)[0] if len(desc) > 100 else desc
        print(f"{name:<{width}}  {first if len(first) <= 100 else first[:97] + '...'}")
    print("\n'thermofriction presets show NAME' prints one as a model file; any command's MODEL takes a preset name.")
    return 0


__all__ = ["add_presets_command", "cmd_presets", "preset_description"]
