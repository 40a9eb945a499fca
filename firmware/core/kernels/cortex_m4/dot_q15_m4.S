@ Cortex-M4 (ARMv7E-M, DSP extension) kernels of firmware/core/kernels/dot_q15.h;
@ their C++ side, with the contracts, is dot_q15.cc next to this file. The
@ job layouts and block sizes are single-sourced in kernel_layout.h, which
@ dot_q15.cc checks against its structs with offsetof; each unrolled loop
@ checks here that its blocks have the size the entry arithmetic assumes.
#include "firmware/core/kernels/cortex_m4/kernel_layout.h"

@ Fails the assembly unless the code from `start` to `end` is `blocks`
@ blocks of `bytes` bytes each (the C++ side enters a loop at end - k * bytes).
        .macro  HADYNET_CHECK_BLOCKS start, end, blocks, bytes
        .if     (\end - \start) != (\blocks * \bytes)
        .error  "an unrolled block is not the size kernel_layout.h says"
        .endif
        .endm
@ Zeroes the four 64-bit accumulators r6:r7, r8:r9, r10:r11, r12:lr.
        .macro  HADYNET_ZERO_ACC4
        mov     r6, #0
        mov     r7, #0
        mov     r8, #0
        mov     r9, #0
        mov     r10, #0
        mov     r11, #0
        mov     r12, #0
        mov     lr, #0
        .endm

@ Enters an 8-block unrolled body that starts at local label 1 (forward) so
@ that its first pass runs only `rem` = count % 8 blocks (all 8 if rem is 0;
@ then it branches to local label 3, placed right before label 1). rem in
@ r4 (a low register, for CBZ); clobbers r4, r5.
        .macro  HADYNET_ENTER_REMAINDER block_bytes
        cbz     r4, 3f
        rsb     r4, r4, #8
        mov     r5, #\block_bytes
        mul     r4, r4, r5
        adr.w   r5, 1f
        add     r4, r4, r5
        orr     r4, r4, #1
        bx      r4
        .endm

        .syntax unified
        .thumb
        .text

@ ---------------------------------------------------------------------------
@ hadynet_matvec_pairs(const HadynetMatvecJob* job)
@ One block = eight columns of two rows, eleven 32-bit instructions (44 bytes):
@   r0 x pointer, r1 W pointer (packed), r2-r5 x words, r6-r9 W words,
@   r10:r11 first row's accumulator (low:high), r12:lr the second row's.

        .macro  HADYNET_MVP_BLOCK
        ldmia.w r0!, {r2-r5}
        ldmia.w r1!, {r6-r9}
        smlald  r10, r11, r6, r2
        smlald  r10, r11, r7, r3
        smlald  r10, r11, r8, r4
        smlald  r10, r11, r9, r5
        ldmia.w r1!, {r6-r9}
        smlald  r12, lr, r6, r2
        smlald  r12, lr, r7, r3
        smlald  r12, lr, r8, r4
        smlald  r12, lr, r9, r5
        .endm

@ One row's rounding, the general case: acc (lo:hi) + half - (acc < 0),
@ >> out_shift, saturated to int16 into lo. r2 = half, r3 = out_shift,
@ r4 = 32 - out_shift; clobbers r5.
        .macro  HADYNET_MVP_ROUND lo, hi
        asr     r5, \hi, #31
        adds    \lo, \lo, r2
        adc     \hi, \hi, #0
        adds    \lo, \lo, r5
        adc     \hi, \hi, r5
        lsr     \lo, \lo, r3
        lsl     r5, \hi, r4
        orr     \lo, \lo, r5
        asr     \hi, \hi, r3
        cmp     \hi, \lo, asr #31               @ fits int32?
        itee    eq
        ssateq  \lo, #16, \lo                   @ yes: saturate to int16
        movwne  \lo, #0x7fff                    @ no: the rail of its sign
        eorne   \lo, \lo, \hi, asr #31
        .endm

@ The same when the sum fits int32 (hi is lo's sign) and so does sum + half
@ (ADDS sets V otherwise), else a branch to `general` (lo + half undone
@ first when only the add overflowed): HADYNET_MVP_ROUND out of line, which
@ branches back to `done`. Adding hi then subtracts 1 from a negative sum
@ (no overflow: lo + half - 1 > INT32_MIN). r2 = half, r3 = out_shift.
        .macro  HADYNET_MVP_ROUND_INT32 lo, hi, general, undo, done
        cmp     \hi, \lo, asr #31
        bne     \general
        adds    \lo, \lo, r2
        bvs     \undo
        add     \lo, \lo, \hi
        asr     \lo, \lo, r3
        ssat    \lo, #16, \lo
\done:
        .endm

        .global hadynet_matvec_pairs
        .type   hadynet_matvec_pairs, %function
        .thumb_func
        .p2align 2
hadynet_matvec_pairs:
        push    {r4-r11, lr}
        sub     sp, sp, #HADYNET_MVP_JOB_BYTES
        ldmia   r0!, {r1-r9}                    @ the job (18 words) onto the stack
        stmia   sp, {r1-r9}
        ldmia   r0, {r1-r9}
        add     r10, sp, #36
        stmia   r10, {r1-r9}
.Lmvp_pair:
        add     r2, sp, #HADYNET_MVP_A_X
        ldmia   r2, {r0, r1, r10, r11, r12, lr} @ x, W, zeroed accumulators (A_X, A_PAIR, ZEROS)
        ldr     pc, [sp, #HADYNET_MVP_A_ENTRY]  @ into the A loop
.Lmvp_a_start:
        .rept   HADYNET_MVP_BLOCKS
        HADYNET_MVP_BLOCK
        .endr
        .global hadynet_mvp_end_a
hadynet_mvp_end_a:
        HADYNET_CHECK_BLOCKS .Lmvp_a_start, hadynet_mvp_end_a, HADYNET_MVP_BLOCKS, HADYNET_MVP_BLOCK_BYTES
        str     r1, [sp, #HADYNET_MVP_A_PAIR]   @ the loop ends at A's next row pair
        ldrd    r8, r9, [sp, #HADYNET_MVP_A_SHIFT]  @ both accumulators <<= a_shift (a_shift, a_shift_rest)
        lsl     r11, r11, r8
        lsr     r2, r10, r9
        orr     r11, r11, r2
        lsl     r10, r10, r8
        lsl     lr, lr, r8
        lsr     r2, r12, r9
        orr     lr, lr, r2
        lsl     r12, r12, r8
        ldrd    r0, r1, [sp, #HADYNET_MVP_B_X]  @ x, W (B_X, B_PAIR)
        ldr     pc, [sp, #HADYNET_MVP_B_ENTRY]  @ into the B loop
.Lmvp_b_start:
        .rept   HADYNET_MVP_BLOCKS
        HADYNET_MVP_BLOCK
        .endr
        .global hadynet_mvp_end_b
hadynet_mvp_end_b:
        HADYNET_CHECK_BLOCKS .Lmvp_b_start, hadynet_mvp_end_b, HADYNET_MVP_BLOCKS, HADYNET_MVP_BLOCK_BYTES
        str     r1, [sp, #HADYNET_MVP_B_PAIR]   @ and B's
        ldmia   sp, {r0-r3}                     @ bias, out, half, out_shift (offsets 0..12)
        ldrd    r6, r7, [r0], #8                @ the pair's biases, sign-extended in
        adds    r10, r10, r6
        adc     r11, r11, r6, asr #31
        adds    r12, r12, r7
        adc     lr, lr, r7, asr #31
        HADYNET_MVP_ROUND_INT32 r10, r11, .Lmvp_general_first, .Lmvp_undo_first, .Lmvp_first_done
        HADYNET_MVP_ROUND_INT32 r12, lr, .Lmvp_general_second, .Lmvp_undo_second, .Lmvp_second_done
        strh    r10, [r1], #2
        strh    r12, [r1], #2
        ldr     r8, [sp, #HADYNET_MVP_PAIRS]
        stmia   sp, {r0-r1}
        subs    r8, r8, #1
        str     r8, [sp, #HADYNET_MVP_PAIRS]
        bne     .Lmvp_pair
        add     sp, sp, #HADYNET_MVP_JOB_BYTES
        pop     {r4-r11, pc}
.Lmvp_undo_first:                               @ sum + half beyond int32
        sub     r10, r10, r2
.Lmvp_general_first:                            @ a sum beyond int32: the general rounding
        ldr     r4, [sp, #HADYNET_MVP_OUT_SHIFT_REST]
        HADYNET_MVP_ROUND r10, r11
        b       .Lmvp_first_done
.Lmvp_undo_second:
        sub     r12, r12, r2
.Lmvp_general_second:
        ldr     r4, [sp, #HADYNET_MVP_OUT_SHIFT_REST]
        HADYNET_MVP_ROUND r12, lr
        b       .Lmvp_second_done
        .size   hadynet_matvec_pairs, . - hadynet_matvec_pairs

@ ---------------------------------------------------------------------------
@ hadynet_tanh_block(v, n, e, d) / hadynet_sigmoid_block(v, n, e, d)
@ activation.h's interpolation on signed table entries (dot_q15.cc builds
@ them from the tanh table and proves them equal): j = x >> shift (floor,
@ negative for x < 0), g = x mod 2^shift, y = (E[j] + D[j] g) >> shift for
@ tanh (shift 7), ssat16((E[j] + D[j] g) >> 9) for sigmoid (shift 8; E holds
@ sigmoid's offset 32769 and its halving). e and d point at entry j = 0.
@   r0 v, r1 n, r2 e, r3 d, r4 x / g, r5 j / D, r6 E / y.
@ One activation's function: entries at steps of 2^shift inputs, result
@ ssat16(sum >> out_shift) (tanh never reaches the rails: the SSAT is its
@ plain shift).
        .macro  HADYNET_ACTIVATION_BLOCK name, shift, out_shift
        .global \name
        .type   \name, %function
        .thumb_func
        .p2align 2
\name:
        push    {r4-r6}
1:
        ldrsh   r4, [r0]
        asr     r5, r4, #\shift                 @ j
        and     r4, r4, #((1 << \shift) - 1)    @ g
        ldr     r6, [r2, r5, lsl #2]            @ E[j]
        ldrsh   r5, [r3, r5, lsl #1]            @ D[j]
        mla     r6, r5, r4, r6
        ssat    r6, #16, r6, asr #\out_shift
        strh    r6, [r0], #2
        subs    r1, r1, #1
        bne     1b
        pop     {r4-r6}
        bx      lr
        .size   \name, . - \name
        .endm

        HADYNET_ACTIVATION_BLOCK hadynet_tanh_block, 7, 7      @ j in [-256, 255]
        HADYNET_ACTIVATION_BLOCK hadynet_sigmoid_block, 8, 9   @ j in [-128, 127]; (32768 + t + 1) >> 1, at most 32767

@ ---------------------------------------------------------------------------
@ hadynet_dot_cols4_q15(w, stride_bytes, g, pairs, out)
@ Four columns of W^T g on a packed matrix with int16 g: per row pair, one
@ word of g (g[2p] low, g[2p + 1] high), one LDRD of each row's four
@ columns (the pair's second row 16 bytes after its first) and eight
@ SMLAL<x><y>, each one 16 x 16 product into a 64-bit accumulator, halves
@ chosen in the instruction: twelve 32-bit instructions (48 bytes) per row
@ pair, 1.5 per MAC.
@   r0 W pointer, r1 stride in bytes, r2 g pointer, r3 g word, r4-r5 W
@   words, r6:r7, r8:r9, r10:r11, r12:lr accumulators; g's end on the stack.
        .macro  HADYNET_COLS4_Q15_PAIR
        ldr.w   r3, [r2], #4
        ldrd    r4, r5, [r0]
        smlalbb r6, r7, r4, r3
        smlaltb r8, r9, r4, r3
        smlalbb r10, r11, r5, r3
        smlaltb r12, lr, r5, r3
        ldrd    r4, r5, [r0, #16]
        smlalbt r6, r7, r4, r3
        smlaltt r8, r9, r4, r3
        smlalbt r10, r11, r5, r3
        smlaltt r12, lr, r5, r3
        add.w   r0, r0, r1
        .endm

        .global hadynet_dot_cols4_q15
        .type   hadynet_dot_cols4_q15, %function
        .thumb_func
        .p2align 2
hadynet_dot_cols4_q15:
        push    {r4-r11, lr}
        and     r4, r3, #7                      @ pairs % 8
        add     r3, r2, r3, lsl #2              @ g's end
        sub     sp, sp, #8
        str     r3, [sp]
        HADYNET_ZERO_ACC4
        @ Enter the 8-pair body so that the first pass does pairs % 8 pairs
        @ (8 if pairs % 8 == 0).
        HADYNET_ENTER_REMAINDER HADYNET_COLS_Q15_PAIR_BYTES
3:
1:
        .rept   8
        HADYNET_COLS4_Q15_PAIR
        .endr
        HADYNET_CHECK_BLOCKS 1b, ., 8, HADYNET_COLS_Q15_PAIR_BYTES
        ldr     r3, [sp]
        cmp     r2, r3
        bne     1b
        add     sp, sp, #8
        ldr     r4, [sp, #36]                   @ out (fifth argument)
        strd    r6, r7, [r4]
        strd    r8, r9, [r4, #8]
        strd    r10, r11, [r4, #16]
        strd    r12, lr, [r4, #24]
        pop     {r4-r11, pc}
        .size   hadynet_dot_cols4_q15, . - hadynet_dot_cols4_q15
