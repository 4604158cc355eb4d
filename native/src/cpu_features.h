/* Instruction sets of the vector paths and the CPU's, read once (internal). */
#ifndef SKINPACK_CPU_FEATURES_H
#define SKINPACK_CPU_FEATURES_H

/* The vector paths, in order: each implies the ones before it. Batch functions take the widest
 * one the CPU has up to a cap (an argument, not a setting, so one test binary checks every path
 * against the scalar code). */
typedef enum { SP_ISA_SCALAR, SP_ISA_AVX2, SP_ISA_AVX512 } sp_isa;

/* The widest path this build has and this CPU and OS run: AVX2 needs AVX2 + FMA3 and the OS
 * saving the ymm state, AVX-512 needs F + DQ + VL and the zmm/mask state. Reads cpuid and xgetbv
 * on the first call only; later calls load the cached answer (a fact of the machine, the same
 * for every caller and thread, so the library stays free of settings). */
sp_isa sp_cpu_isa(void);

/* The answer of sp_cpu_isa() computed afresh (the unit tests compare the two). */
sp_isa sp_cpu_isa_detect(void);

#endif
