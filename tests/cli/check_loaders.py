"""What tools without SKINPACK_packed_skin do with skinpack's files (docs/extension/loaders.md).

    python3 check_loaders.py --skinpack BIN --node NODE --tools TOOLS_DIR --work DIR ASSET.glb

Compact files must be refused (an error, no output) by gltfpack 1.3 (npm), Debian's gltfpack
0.18 and glTF-Transform 4.x (npm); fallback files must come out of each with a skin that is
still there: every vertex's weights sum to 1 (within 1%), none all zero. Tools that are not
installed are reported as skipped.
"""
import argparse
import os
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gltf_read  # noqa: E402


def tools(args):
    found = []
    gltfpack_npm = os.path.join(args.tools, "node_modules", "gltfpack", "cli.js")
    if os.path.exists(gltfpack_npm):
        found.append(("gltfpack 1.3 (npm)", lambda i, o: [args.node, gltfpack_npm, "-i", i, "-o", o]))
    if shutil.which("gltfpack"):
        found.append(("gltfpack 0.18 (Debian)", lambda i, o: ["gltfpack", "-i", i, "-o", o]))
    transform = os.path.join(args.tools, "node_modules", "@gltf-transform", "cli", "bin", "cli.js")
    if os.path.exists(transform):
        found.append(("glTF-Transform copy", lambda i, o: [args.node, transform, "copy", i, o]))
    return found


def skin_problems(path):
    doc = gltf_read.Gltf(path)
    problems = []
    for m, p, prim in doc.primitives():
        influences = doc.influences(prim)
        if influences is None:
            problems.append("mesh %d primitive %d lost JOINTS_0/WEIGHTS_0" % (m, p))
            continue
        bad = [v for v, joints in enumerate(influences) if abs(sum(joints.values()) - 1) > 0.01]
        if bad:
            problems.append("mesh %d primitive %d: %d of %d vertices have weights not summing to 1 (vertex %d: %s)" % (
                m, p, len(bad), len(influences), bad[0], influences[bad[0]]))
    return problems


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--skinpack", required=True)
    parser.add_argument("--node", required=True)
    parser.add_argument("--tools", required=True)
    parser.add_argument("--work", required=True)
    parser.add_argument("asset")
    args = parser.parse_args()
    os.makedirs(args.work, exist_ok=True)
    failures = []
    found = tools(args)
    if not found:
        raise SystemExit("FAILED: none of gltfpack (npm or Debian) or glTF-Transform is installed")
    for kind in ("compact", "fallback"):
        for ext in (".glb", ".gltf"):
            packed = os.path.join(args.work, kind + ext)
            subprocess.run([args.skinpack, "compress", args.asset, "-o", packed, "--" + kind], check=True,
                           capture_output=True)
            for index, (name, command) in enumerate(found):
                out = os.path.join(args.work, "%s%s.tool%d.glb" % (kind, ext.replace(".", "_"), index))
                if os.path.exists(out):
                    os.remove(out)
                result = subprocess.run(command(packed, out), capture_output=True, text=True)
                said = (result.stdout + result.stderr).strip().splitlines()
                said = said[-1] if said else ""
                if kind == "compact":
                    ok = result.returncode != 0 and not os.path.exists(out)
                    verdict = "refused" if ok else "ACCEPTED (exit %d)" % result.returncode
                    if not ok:
                        failures.append("%s accepted the compact %s" % (name, ext))
                else:
                    problems = ["exit %d" % result.returncode] if result.returncode else skin_problems(out)
                    verdict = "skin kept" if not problems else "SKIN LOST: " + "; ".join(problems)
                    failures += ["%s on the fallback %s: %s" % (name, ext, p) for p in problems]
                print("%-8s %-5s %-24s %s -- %s" % (kind, ext, name, verdict, said))
    if failures:
        print("\n".join(failures))
        raise SystemExit("%d problem(s)" % len(failures))
    print("OK: %d tool(s)" % len(found))


if __name__ == "__main__":
    main()
