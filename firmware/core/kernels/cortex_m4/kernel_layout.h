/* The layout the Cortex-M4 assembly (dot_q15_m4.S) and its C++ side
 * (dot_q15.cc) share: byte offsets of the job blocks' fields and the sizes of
 * the unrolled loops. Plain #defines, so that the assembler's preprocessor
 * reads the same numbers as the compiler; dot_q15.cc checks every offset
 * against its structs with offsetof, and the assembly checks every loop's
 * block size (HADYNET_CHECK_BLOCKS). Change a struct, a loop or these numbers
 * together: the build fails otherwise. */
#ifndef HADYNET_FIRMWARE_CORE_KERNELS_CORTEX_M4_KERNEL_LAYOUT_H_
#define HADYNET_FIRMWARE_CORE_KERNELS_CORTEX_M4_KERNEL_LAYOUT_H_

/* hadynet_matvec_pairs: one block = 8 columns of a row pair, 11 32-bit
 * instructions; up to 32 blocks (256 columns) per term. */
#define HADYNET_MVP_BLOCKS 32
#define HADYNET_MVP_BLOCK_BYTES 44
/* HadynetMatvecJob (18 words, copied onto the assembly's stack). A_X,
 * A_PAIR and the four zero words are consecutive: one LDM starts a row pair
 * (x, W, zeroed accumulators); B_X and B_PAIR are consecutive for one LDRD. */
#define HADYNET_MVP_JOB_BYTES 72
#define HADYNET_MVP_BIAS 0
#define HADYNET_MVP_OUT 4
#define HADYNET_MVP_HALF 8
#define HADYNET_MVP_OUT_SHIFT 12
#define HADYNET_MVP_OUT_SHIFT_REST 16
#define HADYNET_MVP_PAIRS 20
#define HADYNET_MVP_A_X 24
#define HADYNET_MVP_A_PAIR 28
#define HADYNET_MVP_ZEROS 32
#define HADYNET_MVP_B_X 48
#define HADYNET_MVP_B_PAIR 52
#define HADYNET_MVP_A_ENTRY 56
#define HADYNET_MVP_B_ENTRY 60
#define HADYNET_MVP_A_SHIFT 64
#define HADYNET_MVP_A_SHIFT_REST 68

/* hadynet_dot_cols4_q15: one row pair of four columns, 12 32-bit instructions. */
#define HADYNET_COLS_Q15_PAIR_BYTES 48

#endif /* HADYNET_FIRMWARE_CORE_KERNELS_CORTEX_M4_KERNEL_LAYOUT_H_ */
