"""The real options of our programs, read from their CLI11 `--help` output, so the deployment checks
compare the container files with what the binaries accept rather than with a copy of the flag list."""

import re
import subprocess
from dataclasses import dataclass


@dataclass
class Option:
    name: str  # "--grpc-listen"
    env: str  # "K4REG_GRPC_LISTEN", or "" when the option has no variable
    default: str  # the displayed default, "" when none is shown


# CLI11 prints one option per line: "  --name TYPE=default (Env:NAME) ...   description"; the description may
# follow on the same line after padding, or on the next line.
_OPTION_LINE = re.compile(r"^\s+(?:-\w,)?(--[\w-]+)(?:\{[^}]*\})?(.*)$")


def parse_help(text):
    """{"--name": Option} for every long option in a CLI11 help text."""
    options = {}
    for line in text.splitlines():
        match = _OPTION_LINE.match(line)
        if not match:
            continue
        name, rest = match.groups()
        env = re.search(r"\(Env:(\w+)\)", rest)
        # The option column ends at "(Env:" or at the padding before the description.
        column = rest[: env.start()] if env else re.split(r"\s{2,}", rest.strip() + "  ")[0]
        default = re.search(r"(?<=\S)=(\S+)", column)
        options[name] = Option(name, env.group(1) if env else "", default.group(1) if default else "")
    return options


def program_options(command):
    """Options of `command` (a list, e.g. [k4reg, "health"]) as its `--help` prints them."""
    done = subprocess.run(list(command) + ["--help"], capture_output=True, text=True, timeout=30)
    if done.returncode != 0 or "Options:" not in done.stdout:
        raise RuntimeError(f"{' '.join(map(str, command))} --help failed: {done.stderr.strip()}")
    return parse_help(done.stdout)


def flags_of(argv):
    """The long options an argument vector uses ("--name" and "--name=value" both give "--name")."""
    return [a.split("=", 1)[0] for a in argv if a.startswith("--")]
