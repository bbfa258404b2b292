// Fixture: long_function is 84 lines, the limit is 80; the others are short.
#include <string>
#define BLOCK_OPEN {
namespace fixture {

int long_function(int x,
                  int y) {
  int total = 0;
  const auto step = [&](int v) {
    total += v;
  };
  step(x + y + 0);
  step(x + y + 1);
  step(x + y + 2);
  step(x + y + 3);
  step(x + y + 4);
  step(x + y + 5);
  step(x + y + 6);
  step(x + y + 7);
  step(x + y + 8);
  step(x + y + 9);
  step(x + y + 10);
  step(x + y + 11);
  step(x + y + 12);
  step(x + y + 13);
  step(x + y + 14);
  step(x + y + 15);
  step(x + y + 16);
  step(x + y + 17);
  step(x + y + 18);
  step(x + y + 19);
  step(x + y + 20);
  step(x + y + 21);
  step(x + y + 22);
  step(x + y + 23);
  step(x + y + 24);
  step(x + y + 25);
  step(x + y + 26);
  step(x + y + 27);
  step(x + y + 28);
  step(x + y + 29);
  step(x + y + 30);
  step(x + y + 31);
  step(x + y + 32);
  step(x + y + 33);
  step(x + y + 34);
  step(x + y + 35);
  step(x + y + 36);
  step(x + y + 37);
  step(x + y + 38);
  step(x + y + 39);
  step(x + y + 40);
  step(x + y + 41);
  step(x + y + 42);
  step(x + y + 43);
  step(x + y + 44);
  step(x + y + 45);
  step(x + y + 46);
  step(x + y + 47);
  step(x + y + 48);
  step(x + y + 49);
  step(x + y + 50);
  step(x + y + 51);
  step(x + y + 52);
  step(x + y + 53);
  step(x + y + 54);
  step(x + y + 55);
  step(x + y + 56);
  step(x + y + 57);
  step(x + y + 58);
  step(x + y + 59);
  step(x + y + 60);
  step(x + y + 61);
  step(x + y + 62);
  step(x + y + 63);
  step(x + y + 64);
  step(x + y + 65);
  step(x + y + 66);
  step(x + y + 67);
  step(x + y + 68);
  step(x + y + 69);
  step(x + y + 70);
  step(x + y + 71);
  step(x + y + 72);
  step(x + y + 73);
  step(x + y + 74);
  step(x + y + 75);
  return total;
}

int short_function() { return 1; }

}  // namespace fixture
