#!/usr/bin/env bash
# Mutation check: applies each mutation of tests/mutations/mutations.txt to a copy of the tree and
# asserts that the tests it names fail (a gtest filter of voxlab_tests, or ctest:REGEX for CTest
# tests of the copy's build). Not part of CI (the copy's first build takes 10 to 30 minutes on this
# shared machine, the 87 mutations about 7 minutes after it; see docs/testing.md).
#
#   scripts/mutation-check.sh [--only NAME[,NAME...]] [--list FILE] [--work DIR]
#   scripts/mutation-check.sh --check-finds    (only checks that every mutation still applies:
#                                               its find text occurs exactly once in its file; CTest
#                                               runs this as source.mutations_apply)
#
# The copy lives in DIR (default build-mutation/ in the repository, ignored by git): DIR/tree is
# the repository's tracked and untracked-but-not-ignored files, DIR/build its own build. Shader
# mutations need no rebuild (the tests read shaders through VOXLAB_ROOT=DIR/tree); C++ mutations
# rebuild DIR/build incrementally, and run after the shader ones. Exit status 0 when every
# mutation is killed, 1 when one survives or does not apply, 2 for bad arguments.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
exec python3 - "$root" "$@" <<'PY'
import os, re, shutil, subprocess, sys, time

root = sys.argv[1]
args = sys.argv[2:]
listFile = os.path.join(root, "tests", "mutations", "mutations.txt")
work = os.path.join(root, "build-mutation")
only = None
checkFinds = False
i = 0
while i < len(args):
    a = args[i]
    if a == "--check-finds":
        checkFinds = True
        i += 1
    elif a in ("--only", "--list", "--work") and i + 1 < len(args):
        if a == "--only": only = set(args[i + 1].split(","))
        if a == "--list": listFile = os.path.abspath(args[i + 1])
        if a == "--work": work = os.path.abspath(args[i + 1])
        i += 2
    else:
        sys.stderr.write("mutation-check: unknown argument '%s'; valid: --only NAMES, --list FILE, --work DIR, --check-finds\n" % a)
        sys.exit(2)

def parse(path):
    blocks, cur = [], {}
    for line in open(path, encoding="utf-8"):
        line = line.rstrip("\n")
        if line.startswith("#"):
            continue
        if not line.strip():
            if cur: blocks.append(cur); cur = {}
            continue
        key, sep, value = line.partition(": ")
        if not sep or key not in ("name", "file", "find", "replace", "tests", "breaks"):
            sys.stderr.write("mutation-check: %s: bad line '%s' (want 'name|file|find|replace|tests|breaks: ...')\n" % (path, line))
            sys.exit(2)
        cur[key] = value
    if cur: blocks.append(cur)
    for b in blocks:
        missing = [k for k in ("name", "file", "find", "replace", "tests", "breaks") if k not in b]
        if missing:
            sys.stderr.write("mutation-check: mutation %s lacks %s\n" % (b.get("name", "?"), ", ".join(missing)))
            sys.exit(2)
    return blocks

mutations = parse(listFile)
if checkFinds:
    stale = []
    for m in mutations:
        path = os.path.join(root, m["file"])
        count = open(path, encoding="utf-8").read().count(m["find"]) if os.path.exists(path) else -1
        if count != 1:
            stale.append("%s: its find text occurs %s in %s (want exactly once)" % (
                m["name"], "no file" if count < 0 else "%d times" % count, m["file"]))
    for line in stale: print("mutation-check: " + line)
    print("mutation-check: %d of %d mutations apply" % (len(mutations) - len(stale), len(mutations)))
    sys.exit(1 if stale else 0)
if only:
    unknown = only - {m["name"] for m in mutations}
    if unknown:
        sys.stderr.write("mutation-check: unknown mutation %s; valid: %s\n" % (", ".join(sorted(unknown)), ", ".join(m["name"] for m in mutations)))
        sys.exit(2)
    mutations = [m for m in mutations if m["name"] in only]
isShader = lambda m: m["file"].startswith("shaders/")
mutations.sort(key=lambda m: (not isShader(m)))  # shaders first: no rebuilds in between

start = time.time()
tree, build = os.path.join(work, "tree"), os.path.join(work, "build")

def run(cmd, env=None, timeout=1800, cwd=None):
    p = subprocess.run(cmd, cwd=cwd or root, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=timeout)
    return p.returncode, p.stdout.decode("utf-8", "replace")

# 1. The copy: tracked and untracked-but-not-ignored files.
os.makedirs(work, exist_ok=True)
log = open(os.path.join(work, "mutation-check.log"), "w")
files = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"], cwd=root,
                       stdout=subprocess.PIPE, check=True).stdout.decode().split("\0")
for f in files:
    if not f or not os.path.isfile(os.path.join(root, f)):
        continue
    dst = os.path.join(tree, f)
    os.makedirs(os.path.dirname(dst), exist_ok=True)
    src = os.path.join(root, f)
    if not os.path.exists(dst) or open(src, "rb").read() != open(dst, "rb").read():
        shutil.copyfile(src, dst)  # a fresh mtime, so that make rebuilds what depends on it
        shutil.copymode(src, dst)
print("mutation-check: building the copy in %s" % build, flush=True)
rc, out = run(["cmake", "-S", tree, "-B", build, "-DCMAKE_BUILD_TYPE=Release"])
rc2, out2 = run(["cmake", "--build", build, "-j2", "--target", "voxlab_tests", "voxlab"]) if rc == 0 else (rc, "")
log.write(out + out2)
if rc or rc2:
    sys.stderr.write("mutation-check: the unmutated copy does not build (see %s)\n" % log.name)
    sys.exit(1)

env = dict(os.environ, VOXLAB_ROOT=tree, LP_NUM_THREADS=os.environ.get("LP_NUM_THREADS", "2"))
testBinary = os.path.join(build, "voxlab_tests")

def gtest(filter_):
    rc, out = run([testBinary, "--gtest_filter=" + filter_], env=env, cwd=build)  # snapshot-failures/ go there
    m = re.search(r"\[==========\] (\d+) tests? from", out)
    return rc, (int(m.group(1)) if m else 0), out

# "tests: ctest:REGEX" names CTest tests of the copy's build instead (command-line cases, scripts
# that run build/voxlab): ctest -R REGEX there, with the same environment.
def ctest(regex):
    rc, out = run(["ctest", "-R", regex, "--output-on-failure"], env=env, cwd=build)
    m = re.search(r"tests passed, \d+ tests? failed out of (\d+)", out)
    return rc, (int(m.group(1)) if m else 0), out

def runTests(spec):
    return ctest(spec[len("ctest:"):]) if spec.startswith("ctest:") else gtest(spec)

# 2. Unmutated, every named test must pass (else a kill proves nothing).
specs = {m["tests"] for m in mutations}
unions = []
gfilters = sorted(t for t in specs if not t.startswith("ctest:"))
cregexes = sorted(t[len("ctest:"):] for t in specs if t.startswith("ctest:"))
if gfilters: unions.append(":".join(gfilters))
if cregexes: unions.append("ctest:" + "|".join("(%s)" % r for r in cregexes))
count = 0
for u in unions:
    rc, n, out = runTests(u)
    log.write(out)
    if rc != 0 or n == 0:
        sys.stderr.write("mutation-check: the named tests fail (or match nothing) without a mutation: %s (see %s)\n" % (u[:200], log.name))
        sys.exit(1)
    count += n
print("mutation-check: %d named tests pass unmutated" % count, flush=True)

# 3. Each mutation.
results = []
cppDirty = False
for m in mutations:
    t0 = time.time()
    path = os.path.join(tree, m["file"])
    original = open(path, encoding="utf-8").read()  # the copy's text (the tree as it was copied)
    n = original.count(m["find"])
    if n != 1:
        results.append((m, "does not apply (%d occurrences)" % n, 0.0))
        print("  %-28s does not apply: '%s' occurs %d times in %s" % (m["name"], m["find"], n, m["file"]), flush=True)
        continue
    open(path, "w", encoding="utf-8").write(original.replace(m["find"], m["replace"]))
    verdict = None
    if not isShader(m) or cppDirty:
        rc, out = run(["cmake", "--build", build, "-j2", "--target", "voxlab_tests", "voxlab"])
        log.write(out)
        if rc != 0:
            verdict = "does not compile"
        cppDirty = not isShader(m)
    if verdict is None:
        rc, count, out = runTests(m["tests"])
        log.write("=== %s\n%s" % (m["name"], out))
        verdict = "killed" if rc != 0 else ("survived" if count else "no tests matched")
    open(path, "w", encoding="utf-8").write(original)
    dt = time.time() - t0
    results.append((m, verdict, dt))
    print("  %-28s %-16s %5.0f s  (%s)" % (m["name"], verdict, dt, m["tests"]), flush=True)
if cppDirty:
    run(["cmake", "--build", build, "-j2", "--target", "voxlab_tests", "voxlab"])

killed = sum(1 for _, v, _ in results if v == "killed")
print("mutation-check: %d of %d mutations killed in %.0f s" % (killed, len(results), time.time() - start))
for m, v, _ in results:
    if v != "killed":
        print("  NOT KILLED: %s (%s): %s" % (m["name"], v, m["breaks"]))
sys.exit(0 if killed == len(results) else 1)
PY
