// The serial N_Vector's elementwise operations, compiled with this project.
//
// Debian 12's SUNDIALS 6.4.1 (libsundials-dev 6.4.1+dfsg1-3, shared and static libraries alike)
// is built without optimization: its serial vector operations keep every loop variable on the
// stack (`mov -0x8(%rbp),%rax` for each element; `gdb -batch -ex 'disassemble Vaxpy_Serial'
// build/railcrash`), about 16 instructions per element of an axpy. IDA calls these operations
// about a hundred times per step, and in the report's two-car crash they were a fifth of the
// run (bench/HISTORY.md, "SUNDIALS's vector operations compiled here").
//
// use_compiled_serial_ops(v) points v's operation table at functions in this file for the
// operations IDA calls every step. Each computes exactly what SUNDIALS 6.4.1's nvector_serial.c
// computes (the same special cases of the coefficients, the same operations in the same order
// on each element, sums accumulated in index order), so a run's numbers are unchanged to the
// bit (tests/solver/test_serial_vector_ops.cpp compares them with SUNDIALS's own). Clones inherit
// the table (N_VClone copies it), so calling it on the vectors IDA is initialized with covers
// every vector IDA makes from them. The fused and vector-array operations stay disabled, as
// SUNDIALS's defaults are: IDA then composes them from these.
#pragma once

#include <nvector/nvector_serial.h>

namespace railcrash {

/// Replaces v's linear sum, scale, constant, absolute value, inverse, constant addition,
/// product, quotient, max norm and (masked) weighted RMS norms by the functions here. v must be
/// a serial vector (N_VNew_Serial).
void use_compiled_serial_ops(N_Vector v);

}  // namespace railcrash
