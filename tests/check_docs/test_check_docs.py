#!/usr/bin/env python3
"""test_check_docs.py - the self-test of tools/check-docs: runs it on
fixture.md (blocks that pass, one saved by a file marker, one marked not
run, one failing in its middle line, one past the time limit, and a
misplaced marker) and checks each verdict, the reported lines and output,
and the final count; then on two pages of a folder of its own, that
docs/install.md runs first and what it exports reaches the other page,
and nothing else of the caller's environment does. Usage:
test_check_docs.py CHECK-DOCS FIXTURE."""
import os
import subprocess
import sys
import tempfile

check, fixture = sys.argv[1], sys.argv[2]
p = subprocess.run([sys.executable, check, "--time-limit", "3", fixture],
                   capture_output=True, text=True, timeout=120)
out = p.stdout
fails = []


def expect(cond, what):
    if not cond:
        fails.append(what)


def line_of(text):
    """The fixture's line number of the first line holding text."""
    with open(fixture, encoding="utf-8") as f:
        for n, s in enumerate(f, 1):
            if text in s:
                return n
    raise SystemExit("fixture lacks %r" % text)


first = line_of("echo made-by-the-first-block") - 1
second = line_of("grep -q made-by-the-first-block") - 1
skipped = line_of("exit 7") - 1
failing = line_of("echo output-before-the-failure") - 1
sleeping = line_of("echo started-sleeping") - 1
marker = line_of("<!-- not run: a misplaced marker -->")

expect(p.returncode == 1, "exit status %d, not 1" % p.returncode)
expect("fixture.md:%d: ok" % first in out, "the first block passes")
expect("fixture.md:%d: ok" % second in out,
       "the second block (indented; file marker, files and exports of the "
       "first, a copy of the source tree) passes")
expect("fixture.md:%d: not run: needs a cluster of 64 machines" % skipped
       in out, "the marked block is listed with its reason")
expect("fixture.md:%d: FAILED (exit status 2" % failing in out,
       "the failing block fails with ls's status")
expect("the command at %s:%d failed" % (fixture, failing + 2) in out,
       "the failing command is named by its line of the page")
expect("output-before-the-failure" in out and
       "no-such-file-in-the-fixture" in out, "the failure's output is shown")
expect("output-after-the-failure" not in out.replace(
    "$ echo output-after-the-failure", ""),
       "nothing runs after the failing command")
expect("fixture.md:%d: FAILED (time limit of 3 s" % sleeping in out,
       "the sleeping block is stopped at the time limit")
expect("fixture.md:%d: FAILED: a '<!-- not run: a misplaced marker -->' "
       "marker must be the line directly above a fence" % marker in out,
       "a marker away from its fence is an error")
expect(out.rstrip().endswith("\n1 not run\n2 passed, 3 failed"),
       "the count ends the output")

# docs/install.md first, its exports for every page, nothing else
with tempfile.TemporaryDirectory() as d:
    os.makedirs(os.path.join(d, "docs"))
    with open(os.path.join(d, "docs", "install.md"), "w") as f:
        f.write("```sh\nexport FIXTURE_PREFIX=\"$HOME/prefix\"\n```\n")
    caller_home = os.environ.get("HOME", "/")
    with open(os.path.join(d, "docs", "use.md"), "w") as f:
        f.write("```sh\ntest \"$FIXTURE_PREFIX\" = \"$HOME/prefix\"\n"
                "test \"$HOME\" != '%s'\n"
                "test -z \"$LD_LIBRARY_PATH$CALLER_ONLY\"\n```\n"
                % caller_home)
    env = dict(os.environ, CALLER_ONLY="x", LD_LIBRARY_PATH="/nowhere",
               HOME=caller_home)
    q = subprocess.run([sys.executable, os.path.abspath(check),
                        "docs/use.md", "docs/install.md"], cwd=d, env=env,
                       capture_output=True, text=True, timeout=120)
    expect(q.returncode == 0 and q.stdout.find("docs/install.md:1: ok") <
           q.stdout.find("docs/use.md:1: ok") and
           q.stdout.rstrip().endswith("2 passed, 0 failed"),
           "docs/install.md runs first and its exports reach the other "
           "page, the caller's environment does not:\n" + q.stdout)

if fails:
    print(out)
    print(p.stderr)
    for f in fails:
        print("FAILED: " + f)
    sys.exit(1)
print("check-docs reports the fixture's 2 passes, 3 failures and 1 block "
      "not run as expected")
