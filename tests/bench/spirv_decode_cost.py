#!/usr/bin/env python3
"""Static SPIR-V cost of the skinning compute shader per decoder path: the one GPU cost figure a
CPU-only machine can measure (docs/benchmarks-gpu.md).

usage: spirv_decode_cost.py SKIN_COMP_SPV
For OSS (method 4) with K = 4 and each decoder (spec constants 1, 2, 3 of skin_common.glsl:
method, influences, decoder 0 = narrow, 1 = wide, 2 = wide with 32-bit rows), the module is specialised and optimised
(spirv-opt --set-spec-const-default-value ... --freeze-spec-const -O), so the other paths fold
away; counted are the instructions inside functions and, of those, the ALU ones (arithmetic,
bit, compare, conversion, select, extended instructions). Static counts: loops count once.
"""
import re
import subprocess
import sys
import tempfile

NOT_ALU = {"OpFunction", "OpFunctionParameter", "OpFunctionEnd", "OpLabel", "OpBranch", "OpBranchConditional",
           "OpSwitch", "OpReturn", "OpReturnValue", "OpLoopMerge", "OpSelectionMerge", "OpPhi", "OpVariable",
           "OpLoad", "OpStore", "OpAccessChain", "OpInBoundsAccessChain", "OpFunctionCall", "OpLine", "OpNoLine",
           "OpCompositeExtract", "OpCompositeConstruct", "OpCompositeInsert", "OpVectorShuffle", "OpCopyObject",
           "OpUnreachable", "OpKill", "OpControlBarrier", "OpMemoryBarrier"}


def cost(spv, decoder):
    with tempfile.NamedTemporaryFile(suffix=".spv") as out:
        subprocess.run(["spirv-opt", "--set-spec-const-default-value", f"1:4 2:4 3:{decoder}", "--freeze-spec-const", "--fold-spec-const-op-composite",
                        "-O", spv, "-o", out.name], check=True)
        text = subprocess.run(["spirv-dis", "--raw-id", out.name], check=True, capture_output=True,
                              text=True).stdout
    inside, total, alu = False, 0, 0
    for line in text.splitlines():
        match = re.search(r"\b(Op[A-Za-z0-9]+)", line)
        if not match:
            continue
        op = match.group(1)
        if op == "OpFunction":
            inside = True
        if inside:
            total += 1
            alu += op not in NOT_ALU
        if op == "OpFunctionEnd":
            inside = False
    return total, alu


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    print("| skin.comp, OSS K = 4 | instructions | ALU instructions |")
    print("|---|---|---|")
    for decoder, name in ((0, "narrow (32-bit) decoder"), (1, "wide decoder, 64-bit row step"),
                          (2, "wide decoder, 32-bit row step (S(N) < 2^32)")):
        total, alu = cost(sys.argv[1], decoder)
        print(f"| {name} | {total} | {alu} |")


if __name__ == "__main__":
    main()
