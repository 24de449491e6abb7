// Does one kind of undefined behaviour or memory error, named by its argument, so that
// sanitizers_test can check what the sanitizer build catches. Exits 0 when nothing stopped it.

#include <cstdio>
#include <cstring>
#include <vector>

#include <Eigen/Core>

namespace {

// Volatile, so that the compiler cannot see the values and fold the faults away.
volatile int g_large = 2147483600;
volatile int g_step = 100;
volatile size_t g_index = 4;

struct Counter {
  int n = 0;
  int Next() { return ++n; }
};
Counter* volatile g_counter = nullptr;

int SignedOverflow() { return g_large + g_step; }

// Our code calls Eigen with a vector too short for it: the read past the end happens inside
// Eigen's inlined code, which UBSan skips and ASan instruments.
double EigenReadPastTheEnd() {
  std::vector<double> values(g_index - 1, 1.0);
  const Eigen::Map<const Eigen::Vector4d> v(values.data());
  return v.sum();
}

int VectorReadPastTheEnd() {
  std::vector<int> values(4, 1);
  return values[g_index];
}

int NullMemberCall() { return g_counter->Next(); }

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: sanitizer_probe signed-overflow|null-member-call|vector-overflow|eigen-overflow\n");
    return 2;
  }
  const char* what = argv[1];
  double result = 0.0;
  if (std::strcmp(what, "signed-overflow") == 0) {
    result = SignedOverflow();
  } else if (std::strcmp(what, "null-member-call") == 0) {
    result = NullMemberCall();
  } else if (std::strcmp(what, "vector-overflow") == 0) {
    result = VectorReadPastTheEnd();
  } else if (std::strcmp(what, "eigen-overflow") == 0) {
    result = EigenReadPastTheEnd();
  } else {
    std::fprintf(stderr, "sanitizer_probe: unknown fault '%s'\n", what);
    return 2;
  }
  std::printf("not stopped: %g\n", result);
  return 0;
}
