#!/usr/bin/env python3
"""The manual cannot drift from the program.

  docs_test.py flags BPM       every flag that `bpm --help` and each command's --help print
                               (render, compare, luminaire) is documented in docs/USAGE.md (a table row whose
                               first cell starts with the flag), and every flag documented there
                               exists.
  docs_test.py examples BPM [--mpi] [--python PYTHON MODULE_DIR]
                               every example marked runnable (a fenced block opened by
                               "```sh runnable") in README.md and docs/*.md runs, at a small
                               resolution and sample count, and exits 0. The blocks of a file run in
                               order in one scratch folder that holds links to scenes/ and
                               examples/, so a later example may read what an earlier one wrote.
                               `mpirun` examples run only with --mpi (bpm built with MPI and mpirun
                               installed); `python3` examples only with --python, under PYTHON
                               with the module from MODULE_DIR and BPM_EXAMPLE_QUICK=1 (the
                               examples then render briefly).
  docs_test.py self-test BPM   the two checks above fail on a flag without documentation, on a
                               documented flag that does not exist and on a broken example.

Each check prints what it found wrong and exits 1 if anything was."""
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
MANUAL_FILES = ["README.md"] + sorted(
    os.path.join("docs", f) for f in os.listdir(os.path.join(ROOT, "docs")) if f.endswith(".md"))

# Examples render at this size; a command's own pass count N becomes the bits of N, 1 + floor(log2
# N) (so that an extended render still asks for more than the one it resumes), and a command
# without one gets SMALL_PASSES.
SMALL_RESOLUTION = "32x24"
SMALL_PASSES = 2
EXAMPLE_TIMEOUT_S = 120


# ---------------------------------------------------------------------------------------------
# Flags

def help_flags(bpm):
    """The long and short flags each command's --help prints, as {flag: command}."""
    flags = {}
    for command in ([], ["render"], ["compare"], ["luminaire"]):
        text = subprocess.run([bpm] + command + ["--help"], capture_output=True, text=True,
                              check=True).stdout
        for line in text.splitlines():
            # An option line starts with its names: "  -o,--output TEXT  ..." or "  --k0 FLOAT".
            m = re.match(r"\s+((?:-{1,2}[A-Za-z][\w-]*,?)+)", line)
            if m:
                for name in m.group(1).split(","):
                    if name and name != "-h" and name != "--help":
                        flags[name] = " ".join(["bpm"] + command)
    return flags


def documented_flags(usage_text):
    """Flags that start the first cell of a table row in docs/USAGE.md: | `--time S` | ... |."""
    flags = set()
    for line in usage_text.splitlines():
        m = re.match(r"\|\s*`([^`]+)`", line)
        if not m:
            continue
        for part in m.group(1).split(","):
            word = part.strip().split(" ")[0]
            if re.fullmatch(r"-{1,2}[A-Za-z][\w-]*", word):
                flags.add(word)
    return flags


def check_flags(bpm, usage_text):
    problems = []
    printed = help_flags(bpm)
    documented = documented_flags(usage_text)
    for flag in sorted(set(printed) - documented):
        problems.append(f"{flag} ({printed[flag]} --help) is not documented in docs/USAGE.md")
    for flag in sorted(documented - set(printed)):
        problems.append(f"{flag} is documented in docs/USAGE.md but no command has it")
    if not printed:
        problems.append("no flag found in the --help output")
    return problems


# ---------------------------------------------------------------------------------------------
# Examples

def runnable_blocks(path):
    """(line number, [commands]) of each ```sh runnable block; a command may continue with \\."""
    blocks = []
    lines = open(path, encoding="utf-8").read().splitlines()
    i = 0
    while i < len(lines):
        if re.match(r"^\s*```sh runnable\s*$", lines[i]):
            start = i + 1
            commands, current = [], ""
            i += 1
            while i < len(lines) and not lines[i].strip().startswith("```"):
                line = lines[i].strip()
                i += 1
                if line.startswith("#") and not current:
                    continue
                if line.endswith("\\"):
                    current += line[:-1] + " "
                    continue
                current += line
                if current.strip():
                    commands.append(current.strip())
                current = ""
            blocks.append((start, commands))
        i += 1
    return blocks


def shrink(args):
    """A bpm render's arguments at the small resolution and sample count, quiet."""
    out, i = [], 0
    has_passes = False
    while i < len(args):
        a = args[i]
        if a == "--resolution" and i + 1 < len(args):
            out += [a, SMALL_RESOLUTION]
            i += 2
            continue
        if a in ("--spp", "--iterations") and i + 1 < len(args):
            out += [a, str(int(args[i + 1]).bit_length())]
            has_passes = True
            i += 2
            continue
        out.append(a)
        i += 1
    if "--resolution" not in out:
        out += ["--resolution", SMALL_RESOLUTION]
    if not has_passes:
        out += ["--spp", str(SMALL_PASSES)]
    if "-q" not in out and "--quiet" not in out:
        out.append("-q")
    return out


def prepare(command, bpm, mpi, python=None):
    """The command as the test runs it (a list), or None when it cannot run here."""
    words = shlex.split(command, comments=True)
    if not words:
        return None
    if words[0] == "python3":
        return [python] + words[1:] if python else None
    prefix = []
    if words[0] == "mpirun":
        if not mpi:
            return None
        k = words.index("bpm")
        prefix = ["mpirun", "--oversubscribe", "-x", "ASAN_OPTIONS"] + words[1:k]
        words = words[k:]
    if words[0] != "bpm":
        raise ValueError(f"a runnable example must be a bpm, mpirun or python3 command: {command}")
    args = words[1:]
    if args and args[0] == "render":
        args = shrink(args)
    return prefix + [bpm] + args


def run_examples(bpm, mpi, files=None, python=None):
    """python: (interpreter, the module's folder), or None to skip python3 examples."""
    problems = []
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               ASAN_OPTIONS=os.environ.get("ASAN_OPTIONS", "detect_leaks=0"),
               BPM_EXAMPLE_QUICK="1")
    if python:
        env["PYTHONPATH"] = os.pathsep.join(
            [os.path.abspath(python[1])] + ([env["PYTHONPATH"]] if env.get("PYTHONPATH") else []))
    count = 0
    for rel in files or MANUAL_FILES:
        path = rel if os.path.isabs(rel) else os.path.join(ROOT, rel)
        blocks = runnable_blocks(path)
        if not blocks:
            continue
        scratch = tempfile.mkdtemp(prefix="bpm-docs-")
        try:
            for folder in ("scenes", "examples"):
                os.symlink(os.path.join(ROOT, folder), os.path.join(scratch, folder))
            for line, commands in blocks:
                for command in commands:
                    try:
                        argv = prepare(command, bpm, mpi, python[0] if python else None)
                    except ValueError as e:
                        problems.append(f"{rel}:{line}: {e}")
                        continue
                    if argv is None:
                        print(f"{rel}:{line}: skipped (no MPI or no Python module here): "
                              f"{command}")
                        continue
                    count += 1
                    try:
                        r = subprocess.run(argv, cwd=scratch, env=env, capture_output=True,
                                           text=True, timeout=EXAMPLE_TIMEOUT_S)
                        ok, why = r.returncode == 0, f"exit status {r.returncode}"
                        tail = (r.stderr or r.stdout).strip().splitlines()[-3:]
                    except subprocess.TimeoutExpired:
                        ok, why, tail = False, f"timed out after {EXAMPLE_TIMEOUT_S} s", []
                    print(f"{rel}:{line}: {'ok' if ok else 'FAILED'}: {command}")
                    if not ok:
                        problems.append(f"{rel}:{line}: `{command}` ran as "
                                        f"`{shlex.join(argv)}`: {why}: " + " / ".join(tail))
        finally:
            shutil.rmtree(scratch, ignore_errors=True)
    if count == 0:
        problems.append("no runnable example found in README.md or docs/")
    return problems


# ---------------------------------------------------------------------------------------------

def self_test(bpm):
    """The checks catch drift: each of these must report a problem."""
    usage = open(os.path.join(ROOT, "docs", "USAGE.md"), encoding="utf-8").read()
    failures = []
    dropped = re.sub(r"^\|\s*`--seed[^\n]*\n", "", usage, flags=re.M)
    if dropped == usage or not any("--seed" in p for p in check_flags(bpm, dropped)):
        failures.append("removing --seed from docs/USAGE.md was not caught")
    invented = usage + "\n| `--no-such-flag` | x | x |\n"
    if not any("--no-such-flag" in p for p in check_flags(bpm, invented)):
        failures.append("documenting --no-such-flag was not caught")
    with tempfile.NamedTemporaryFile("w", suffix=".md", delete=False) as f:
        f.write("```sh runnable\nbpm render scenes/cornell-box.pbrt --no-such-flag\n```\n"
                "```sh runnable\nbpm render scenes/no-such-scene.pbrt\n```\n")
    try:
        broken = run_examples(bpm, False, [f.name])
    finally:
        os.unlink(f.name)
    if len(broken) != 2:
        failures.append(f"two broken examples gave {len(broken)} problem(s): {broken}")
    return failures


def main():
    if len(sys.argv) < 3 or sys.argv[1] not in ("flags", "examples", "self-test"):
        print(__doc__, file=sys.stderr)
        return 2
    what, bpm = sys.argv[1], os.path.abspath(sys.argv[2])
    if what == "flags":
        problems = check_flags(bpm, open(os.path.join(ROOT, "docs", "USAGE.md"),
                                         encoding="utf-8").read())
    elif what == "examples":
        rest = sys.argv[3:]
        python = None
        if "--python" in rest:
            k = rest.index("--python")
            python = (rest[k + 1], rest[k + 2])
        problems = run_examples(bpm, "--mpi" in rest and shutil.which("mpirun"), python=python)
    else:
        problems = self_test(bpm)
    for p in problems:
        print(p)
    print(f"docs_test {what}: {'ok' if not problems else f'{len(problems)} problem(s)'}")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
