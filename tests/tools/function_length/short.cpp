// Fixture for tests/tools/check_function_length_test.py: every function here
// is short (at most 80 lines), whatever the constructs around it.
#include <string>
#define BLOCK_OPEN {
namespace fixture {
namespace {

enum class Kind { a, b, c };
constexpr int kTable[] = {1, 2, 3};

// A raw string full of braces is not code.
const char* kPage = R"html(
<script>function f() { if (x) { y(); } </script>
{{{{{{{{
)html";

auto namespace_lambda = [](int x) {
  return x + 1;
};

}  // namespace

class Widget {
 public:
  Widget(int a, int b) : a_{a}, b_(b), name_{"{"} {
    char brace = '{';
    (void)brace;
  }
  explicit Widget(unsigned n) : a_(static_cast<int>(unsigned{n} * 2)), b_{0} {}
  Widget& operator=(const Widget& other) {
    a_ = other.a_;
    return *this;
  }
  int sum() const noexcept { return a_ + b_; }
  struct Inner {
    int twice(int x) const { return 2 * x; }
  };

 private:
  int a_{0};
  int b_ = 1'000;
  std::string name_;
};

template <typename T>
auto multi_line_signature(T first,
                          T second)
    -> T {
  const auto add = [&](T x) {
    return x + first;
  };
  return add(second);
}

}  // namespace fixture
