// railcrash's compiled serial vector operations against SUNDIALS's own, bit for bit
// (include/railcrash/solver/serial_vector_ops.hpp): every coefficient case of the linear sum and the
// scale, every aliasing of the result with an operand, and the norms.
#include <catch2/catch.hpp>

#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <vector>

#include "railcrash/solver/serial_vector_ops.hpp"

namespace {

struct Context {
  SUNContext context = nullptr;
  Context() { SUNContext_Create(nullptr, &context); }
  ~Context() { SUNContext_Free(&context); }
};

struct VectorDeleter {
  void operator()(N_Vector v) const { N_VDestroy(v); }
};
using Vector = std::unique_ptr<std::remove_pointer_t<N_Vector>, VectorDeleter>;

/// Two vectors with the same entries: one with SUNDIALS's operations, one with ours.
struct Pair {
  Vector theirs, ours;
  Pair(SUNContext context, const std::vector<double>& values)
      : theirs(N_VNew_Serial(static_cast<sunindextype>(values.size()), context)),
        ours(N_VNew_Serial(static_cast<sunindextype>(values.size()), context)) {
    railcrash::use_compiled_serial_ops(ours.get());
    std::memcpy(N_VGetArrayPointer(theirs.get()), values.data(), values.size() * sizeof(double));
    std::memcpy(N_VGetArrayPointer(ours.get()), values.data(), values.size() * sizeof(double));
  }
  bool same() const {
    return std::memcmp(N_VGetArrayPointer(theirs.get()), N_VGetArrayPointer(ours.get()),
                       static_cast<std::size_t>(N_VGetLength(ours.get())) * sizeof(double)) == 0;
  }
};

std::vector<double> random_values(std::mt19937_64& random, int n) {
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-30, 30);
  std::vector<double> values(static_cast<std::size_t>(n));
  for (double& v : values) v = std::ldexp(mantissa(random), exponent(random));
  values[0] = 0.0;
  return values;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

}  // namespace

TEST_CASE("compiled serial vector operations give SUNDIALS's results to the bit", "[integrators]") {
  Context context;
  std::mt19937_64 random(20261127);
  const int n = 123;  // not a multiple of a vector width
  const std::vector<double> coefficients{1.0, -1.0, 0.0, 2.5, -2.5, 0.1, 1.0 / 3.0, -7.0e-3};

  SECTION("linear sum, every coefficient case and every aliasing") {
    for (const double a : coefficients)
      for (const double b : coefficients)
        for (int alias = 0; alias < 3; ++alias) {  // z distinct, z = x, z = y
          const std::vector<double> x = random_values(random, n), y = random_values(random, n),
                                    z = random_values(random, n);
          Pair px(context.context, x), py(context.context, y), pz(context.context, z);
          Pair& result = alias == 1 ? px : alias == 2 ? py : pz;
          N_VLinearSum_Serial(a, px.theirs.get(), b, py.theirs.get(), result.theirs.get());
          N_VLinearSum(a, px.ours.get(), b, py.ours.get(), result.ours.get());
          INFO("a = " << a << ", b = " << b << ", alias " << alias);
          CHECK(result.same());
        }
  }

  SECTION("scale, constant, absolute value, inverse, constant addition, product, quotient") {
    for (const double c : coefficients)
      for (int alias = 0; alias < 2; ++alias) {
        const std::vector<double> x = random_values(random, n), z = random_values(random, n);
        Pair px(context.context, x), pz(context.context, z);
        Pair& result = alias == 1 ? px : pz;
        N_VScale_Serial(c, px.theirs.get(), result.theirs.get());
        N_VScale(c, px.ours.get(), result.ours.get());
        INFO("c = " << c << ", alias " << alias);
        CHECK(result.same());
      }
    std::vector<double> x = random_values(random, n), y = random_values(random, n);
    x[0] = 0.5;  // no division by zero
    y[0] = -0.25;
    Pair px(context.context, x), py(context.context, y), pz(context.context, random_values(random, n));
    N_VConst_Serial(0.75, pz.theirs.get());
    N_VConst(0.75, pz.ours.get());
    CHECK(pz.same());
    N_VAbs_Serial(px.theirs.get(), pz.theirs.get());
    N_VAbs(px.ours.get(), pz.ours.get());
    CHECK(pz.same());
    N_VInv_Serial(px.theirs.get(), pz.theirs.get());
    N_VInv(px.ours.get(), pz.ours.get());
    CHECK(pz.same());
    N_VAddConst_Serial(px.theirs.get(), -3.0e-5, pz.theirs.get());
    N_VAddConst(px.ours.get(), -3.0e-5, pz.ours.get());
    CHECK(pz.same());
    N_VProd_Serial(px.theirs.get(), py.theirs.get(), pz.theirs.get());
    N_VProd(px.ours.get(), py.ours.get(), pz.ours.get());
    CHECK(pz.same());
    N_VDiv_Serial(px.theirs.get(), py.theirs.get(), pz.theirs.get());
    N_VDiv(px.ours.get(), py.ours.get(), pz.ours.get());
    CHECK(pz.same());
  }

  SECTION("norms") {
    for (int trial = 0; trial < 20; ++trial) {
      const std::vector<double> x = random_values(random, n), w = random_values(random, n);
      std::vector<double> id(static_cast<std::size_t>(n));
      for (std::size_t i = 0; i < id.size(); ++i) id[i] = i % 3 == 0 ? 0.0 : 1.0;  // as IDASetId's 0 / 1
      Pair px(context.context, x), pw(context.context, w), pid(context.context, id);
      CHECK(same_bits(N_VMaxNorm(px.ours.get()), N_VMaxNorm_Serial(px.theirs.get())));
      CHECK(same_bits(N_VWrmsNorm(px.ours.get(), pw.ours.get()), N_VWrmsNorm_Serial(px.theirs.get(), pw.theirs.get())));
      CHECK(same_bits(N_VWrmsNormMask(px.ours.get(), pw.ours.get(), pid.ours.get()),
                      N_VWrmsNormMask_Serial(px.theirs.get(), pw.theirs.get(), pid.theirs.get())));
      CHECK(same_bits(N_VWSqrSumLocal(px.ours.get(), pw.ours.get()), N_VWSqrSumLocal_Serial(px.theirs.get(), pw.theirs.get())));
      CHECK(same_bits(N_VWSqrSumMaskLocal(px.ours.get(), pw.ours.get(), pid.ours.get()),
                      N_VWSqrSumMaskLocal_Serial(px.theirs.get(), pw.theirs.get(), pid.theirs.get())));
    }
  }

  SECTION("a clone keeps the compiled operations") {
    Pair px(context.context, random_values(random, n));
    Vector clone(N_VClone(px.ours.get()));
    CHECK(clone->ops->nvlinearsum == px.ours->ops->nvlinearsum);
    CHECK(clone->ops->nvlinearsum != px.theirs->ops->nvlinearsum);
  }
}
