"""A Dockerfile reader: just enough of the format for the deployment checks (stages, instructions,
exec-form arguments, ENV, HEALTHCHECK). Follows the Dockerfile reference: `#` comment lines, `\\` line
continuation (comment lines inside a continuation are dropped), instruction keywords case-insensitive."""

import json
import re
import shlex
from dataclasses import dataclass, field


@dataclass
class Instruction:
    keyword: str  # upper case
    arguments: str
    line: int  # 1-based, where the instruction starts


@dataclass
class Stage:
    image: str
    name: str  # "" when the FROM has no AS
    instructions: list = field(default_factory=list)

    def all(self, keyword):
        return [i for i in self.instructions if i.keyword == keyword]

    def last(self, keyword):
        found = self.all(keyword)
        return found[-1] if found else None


def parse(text):
    """The stages of a Dockerfile, in order. Raises ValueError on an instruction before the first FROM."""
    stages = []
    logical, start = "", 0
    for number, raw in enumerate(text.splitlines(), 1):
        stripped = raw.strip()
        if not stripped or stripped.startswith("#"):
            continue
        if not logical:
            start = number
        if stripped.endswith("\\"):
            logical += stripped[:-1] + " "
            continue
        logical += stripped
        keyword, _, arguments = logical.strip().partition(" ")
        instruction = Instruction(keyword.upper(), arguments.strip(), start)
        logical = ""
        if instruction.keyword == "FROM":
            words = instruction.arguments.split()
            name = words[2] if len(words) == 3 and words[1].upper() == "AS" else ""
            stages.append(Stage(words[0], name))
        elif not stages:
            raise ValueError(f"line {start}: {instruction.keyword} before the first FROM")
        else:
            stages[-1].instructions.append(instruction)
    if logical:
        raise ValueError("the file ends inside a line continuation")
    return stages


def exec_form(arguments):
    """The argument list of an exec-form (JSON array) instruction, or None for the shell form."""
    if not arguments.startswith("["):
        return None
    try:
        value = json.loads(arguments)
    except json.JSONDecodeError:
        return None  # Docker runs a malformed JSON array in the shell form
    return value if isinstance(value, list) and all(isinstance(v, str) for v in value) else None


def env(stage):
    """The variables the stage's ENV instructions set (key=value pairs, or the legacy `ENV key value`)."""
    variables = {}
    for instruction in stage.all("ENV"):
        words = shlex.split(instruction.arguments)
        if words and "=" not in words[0]:
            variables[words[0]] = instruction.arguments.split(None, 1)[1] if len(words) > 1 else ""
            continue
        for word in words:
            name, _, value = word.partition("=")
            variables[name] = value
    return variables


def healthcheck(stage):
    """(options, command) of the stage's effective HEALTHCHECK: options like {"interval": "10s"} and the
    exec-form command (None for the shell form), or None when there is none or it is NONE."""
    instruction = stage.last("HEALTHCHECK")
    if instruction is None or instruction.arguments.upper() == "NONE":
        return None
    match = re.match(r"((?:--[a-z-]+=\S+\s+)*)CMD\s+(.*)", instruction.arguments, re.S)
    if not match:
        raise ValueError(f"line {instruction.line}: HEALTHCHECK without CMD")
    options = dict(re.findall(r"--([a-z-]+)=(\S+)", match.group(1)))
    return options, exec_form(match.group(2).strip())


def copied_from(stage, source_stage):
    """{file name in the image: (source path, destination directory)} of `COPY --from=<source_stage>` lines
    whose destination is a directory (ends with /)."""
    files = {}
    for instruction in stage.all("COPY"):
        words = instruction.arguments.split()
        if f"--from={source_stage}" not in words:
            continue
        paths = [w for w in words if not w.startswith("--")]
        destination = paths[-1]
        if not destination.endswith("/"):
            continue
        for source in paths[:-1]:
            files[source.rsplit("/", 1)[-1]] = (source, destination)
    return files
