#!/usr/bin/env python3
"""Keys of the clang-tidy results that .ci/lint may reuse (docs/static-checks.md).

clang-tidy is a pure function of what it reads: its own version, the .clang-tidy and
.clang-format files, the compile command, and the contents of every file the translation unit
includes. The key of a unit is a SHA-256 over all of these, so two runs with the same key see
byte-identical input and give the same findings. .ci/lint-passed.txt lists the keys of units
that had no finding; .ci/lint skips a unit only when its current key is listed there.

The included files are those `c++ -M` lists for the unit's own compile command (the compile
database's compiler, GCC in the default build), paths under the repository or the build
directory written relative to them, so a checkout anywhere gives the same keys.

Usage: lint_cache.py BUILD_DIR FILE...   prints "KEY FILE" for each FILE (relative to the
repository root), in the order given. Exit status 2 when a FILE is not in the compile database.
"""

import concurrent.futures
import hashlib
import json
import os
import re
import shlex
import subprocess
import sys

ROOT = os.path.realpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
CONFIG_FILES = (".clang-tidy", ".clang-format")


# The generated header that records `git describe` (cmake/git_describe.cmake) changes with
# every commit but holds one string literal, which no check reads; hashed without the literal,
# so the units that include it (the output metadata) keep their recorded passes.
GIT_DESCRIBE_HEADER = os.path.join("generated", "mresim", "core", "git_describe.hpp")
GIT_DESCRIBE_VALUE = re.compile(rb'(kGitDescribe = )"[^"]*"')


def file_digest(path, cache={}):  # pylint: disable=dangerous-default-value
    """SHA-256 of a file's bytes, memoised: the system headers repeat across units."""
    if path not in cache:
        with open(path, "rb") as f:
            data = f.read()
        if path.endswith(GIT_DESCRIBE_HEADER):
            data = GIT_DESCRIBE_VALUE.sub(rb'\1"@GIT_DESCRIBE@"', data)
        cache[path] = hashlib.sha256(data).hexdigest()
    return cache[path]


def normalise(text, build):
    """The repository and build directories as placeholders, so keys do not depend on where
    the checkout lies."""
    return text.replace(build, "@BUILD@").replace(ROOT, "@ROOT@")


def compile_arguments(entry):
    """The compile command as a list, without a compiler launcher (ccache) and without the
    output file, so that it can be re-run with -M."""
    args = entry["arguments"] if "arguments" in entry else shlex.split(entry["command"])
    if os.path.basename(args[0]) == "ccache":
        args = args[1:]
    kept, skip = [], False
    for a in args:
        if skip:
            skip = False
            continue
        if a == "-o":
            skip = True
            continue
        if a == "-c":
            continue
        kept.append(a)
    return kept


def dependencies(entry, args):
    """Every file the unit includes (and the unit itself), as `c++ -M` lists them."""
    out = subprocess.run(args + ["-M", "-MF", "/dev/stdout"], cwd=entry["directory"],
                         check=True, capture_output=True, text=True).stdout
    paths = out.replace("\\\n", " ").split(":", 1)[1].split()
    return {os.path.realpath(os.path.join(entry["directory"], p)) for p in paths}


def unit_key(entry, build, common):
    args = compile_arguments(entry)
    h = hashlib.sha256(common.encode())
    h.update(normalise(" ".join(a for a in args if os.path.realpath(
        os.path.join(entry["directory"], a)) != os.path.realpath(entry["file"])), build).encode())
    for name, path in sorted((normalise(p, build), p) for p in dependencies(entry, args)):
        h.update(f"\n{name} {file_digest(path)}".encode())
    return h.hexdigest()


def common_input():
    """What every unit's result depends on besides its own input."""
    version = subprocess.run(["clang-tidy", "--version"], check=True, capture_output=True,
                             text=True).stdout
    parts = [version]
    for name in CONFIG_FILES:
        path = os.path.join(ROOT, name)
        parts.append(f"{name} {file_digest(path) if os.path.exists(path) else 'absent'}")
    return "\n".join(parts)


def main(argv):
    if len(argv) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    build = os.path.realpath(argv[1])
    with open(os.path.join(build, "compile_commands.json"), encoding="utf-8") as f:
        database = {os.path.realpath(e["file"]): e for e in json.load(f)}
    entries = []
    for name in argv[2:]:
        entry = database.get(os.path.realpath(os.path.join(ROOT, name)))
        if entry is None:
            print(f"lint_cache: {name} is not in {build}/compile_commands.json", file=sys.stderr)
            return 2
        entries.append(entry)
    common = common_input()
    with concurrent.futures.ThreadPoolExecutor(max_workers=os.cpu_count() or 1) as pool:
        keys = list(pool.map(lambda e: unit_key(e, build, common), entries))
    for key, name in zip(keys, argv[2:]):
        print(key, name)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
