#include "railcrash/solver/serial_vector_ops.hpp"

#include <cmath>

// Each function follows SUNDIALS 6.4.1's src/nvector/serial/nvector_serial.c operation for
// operation (see the header); compiled with -ffp-contract=off (CMakeLists.txt) so that no
// multiply and add fuse into one rounding where SUNDIALS rounds twice.

namespace railcrash {

namespace {

using Index = sunindextype;

Index length(N_Vector v) { return NV_LENGTH_S(v); }
realtype* data(N_Vector v) { return NV_DATA_S(v); }

/// y += a x, with a = 1 and a = -1 as an addition and a subtraction.
void axpy(realtype a, N_Vector x, N_Vector y) {
  const Index n = length(x);
  const realtype* xd = data(x);
  realtype* yd = data(y);
  if (a == 1.0) {
    for (Index i = 0; i < n; ++i) yd[i] += xd[i];
  } else if (a == -1.0) {
    for (Index i = 0; i < n; ++i) yd[i] -= xd[i];
  } else {
    for (Index i = 0; i < n; ++i) yd[i] += a * xd[i];
  }
}

/// z = a x + b y, by SUNDIALS's cases of the coefficients in SUNDIALS's order.
void linear_sum(realtype a, N_Vector x, realtype b, N_Vector y, N_Vector z) {
  if (b == 1.0 && z == y) return axpy(a, x, y);
  if (a == 1.0 && z == x) return axpy(b, y, x);
  const Index n = length(x);
  const realtype* xd = data(x);
  const realtype* yd = data(y);
  realtype* zd = data(z);
  if (a == 1.0 && b == 1.0) {
    for (Index i = 0; i < n; ++i) zd[i] = xd[i] + yd[i];
  } else if (a == 1.0 && b == -1.0) {
    for (Index i = 0; i < n; ++i) zd[i] = xd[i] - yd[i];
  } else if (a == -1.0 && b == 1.0) {
    for (Index i = 0; i < n; ++i) zd[i] = yd[i] - xd[i];
  } else if (a == 1.0) {
    for (Index i = 0; i < n; ++i) zd[i] = (b * yd[i]) + xd[i];
  } else if (b == 1.0) {
    for (Index i = 0; i < n; ++i) zd[i] = (a * xd[i]) + yd[i];
  } else if (a == -1.0) {
    for (Index i = 0; i < n; ++i) zd[i] = (b * yd[i]) - xd[i];
  } else if (b == -1.0) {
    for (Index i = 0; i < n; ++i) zd[i] = (a * xd[i]) - yd[i];
  } else if (a == b) {
    for (Index i = 0; i < n; ++i) zd[i] = a * (xd[i] + yd[i]);
  } else if (a == -b) {
    for (Index i = 0; i < n; ++i) zd[i] = a * (xd[i] - yd[i]);
  } else {
    for (Index i = 0; i < n; ++i) zd[i] = (a * xd[i]) + (b * yd[i]);
  }
}

/// z = c x (in place when z is x; a copy for c = 1, a negation for c = -1).
void scale(realtype c, N_Vector x, N_Vector z) {
  const Index n = length(x);
  const realtype* xd = data(x);
  realtype* zd = data(z);
  if (z == x) {
    for (Index i = 0; i < n; ++i) zd[i] *= c;
  } else if (c == 1.0) {
    for (Index i = 0; i < n; ++i) zd[i] = xd[i];
  } else if (c == -1.0) {
    for (Index i = 0; i < n; ++i) zd[i] = -xd[i];
  } else {
    for (Index i = 0; i < n; ++i) zd[i] = c * xd[i];
  }
}

void constant(realtype c, N_Vector z) {
  const Index n = length(z);
  realtype* zd = data(z);
  for (Index i = 0; i < n; ++i) zd[i] = c;
}

void absolute(N_Vector x, N_Vector z) {
  const Index n = length(x);
  const realtype* xd = data(x);
  realtype* zd = data(z);
  for (Index i = 0; i < n; ++i) zd[i] = std::fabs(xd[i]);
}

void inverse(N_Vector x, N_Vector z) {
  const Index n = length(x);
  const realtype* xd = data(x);
  realtype* zd = data(z);
  for (Index i = 0; i < n; ++i) zd[i] = 1.0 / xd[i];
}

void add_constant(N_Vector x, realtype b, N_Vector z) {
  const Index n = length(x);
  const realtype* xd = data(x);
  realtype* zd = data(z);
  for (Index i = 0; i < n; ++i) zd[i] = xd[i] + b;
}

void product(N_Vector x, N_Vector y, N_Vector z) {
  const Index n = length(x);
  const realtype* xd = data(x);
  const realtype* yd = data(y);
  realtype* zd = data(z);
  for (Index i = 0; i < n; ++i) zd[i] = xd[i] * yd[i];
}

void quotient(N_Vector x, N_Vector y, N_Vector z) {
  const Index n = length(x);
  const realtype* xd = data(x);
  const realtype* yd = data(y);
  realtype* zd = data(z);
  for (Index i = 0; i < n; ++i) zd[i] = xd[i] / yd[i];
}

realtype max_norm(N_Vector x) {
  const Index n = length(x);
  const realtype* xd = data(x);
  realtype largest = 0.0;
  for (Index i = 0; i < n; ++i)
    if (std::fabs(xd[i]) > largest) largest = std::fabs(xd[i]);
  return largest;
}

/// sum over i of (x_i w_i)^2, in index order.
realtype weighted_square_sum(N_Vector x, N_Vector w) {
  const Index n = length(x);
  const realtype* xd = data(x);
  const realtype* wd = data(w);
  realtype sum = 0.0;
  for (Index i = 0; i < n; ++i) {
    const realtype product_i = xd[i] * wd[i];
    sum += product_i * product_i;
  }
  return sum;
}

/// The same over the entries whose id is positive.
realtype weighted_square_sum_masked(N_Vector x, N_Vector w, N_Vector id) {
  const Index n = length(x);
  const realtype* xd = data(x);
  const realtype* wd = data(w);
  const realtype* idd = data(id);
  realtype sum = 0.0;
  for (Index i = 0; i < n; ++i) {
    if (idd[i] > 0.0) {
      const realtype product_i = xd[i] * wd[i];
      sum += product_i * product_i;
    }
  }
  return sum;
}

/// SUNDIALS's SUNRsqrt: zero for a non-positive argument.
realtype root(realtype value) { return value <= 0.0 ? 0.0 : std::sqrt(value); }

realtype weighted_rms_norm(N_Vector x, N_Vector w) {
  return root(weighted_square_sum(x, w) / static_cast<realtype>(length(x)));
}

realtype weighted_rms_norm_masked(N_Vector x, N_Vector w, N_Vector id) {
  return root(weighted_square_sum_masked(x, w, id) / static_cast<realtype>(length(x)));
}

}  // namespace

void use_compiled_serial_ops(N_Vector v) {
  N_Vector_Ops ops = v->ops;
  ops->nvlinearsum = linear_sum;
  ops->nvscale = scale;
  ops->nvconst = constant;
  ops->nvabs = absolute;
  ops->nvinv = inverse;
  ops->nvaddconst = add_constant;
  ops->nvprod = product;
  ops->nvdiv = quotient;
  ops->nvmaxnorm = max_norm;
  ops->nvwrmsnorm = weighted_rms_norm;
  ops->nvwrmsnormmask = weighted_rms_norm_masked;
  ops->nvwsqrsumlocal = weighted_square_sum;
  ops->nvwsqrsummasklocal = weighted_square_sum_masked;
}

}  // namespace railcrash
