// The best K (cost, frame) pairs of a query, kept sorted in the strict pair
// order of search_layout.glsl (an empty slot is (kNone, kNone) and loses to
// every candidate). Shared by the scans, which insert rows, and the merges,
// which insert pairs. Needs K (kernel_shape.glsl) and search_layout.glsl.
#ifndef MMVK_TOP_K_GLSL
#define MMVK_TOP_K_GLSL

void clear_pairs(out uvec2 best[K]) {
  [[unroll]] for (uint j = 0; j < K; ++j) best[j] = uvec2(kNone, kNone);
}

// Inserts `candidate` when it is less than the last kept pair; returns
// whether it did. One bubble pass keeps the order (the loop is unrolled:
// llvmpipe's loop limit).
bool insert_pair(inout uvec2 best[K], uvec2 candidate) {
  if (!pair_less(candidate, best[K - 1u])) return false;
  best[K - 1u] = candidate;
  [[unroll]] for (uint j = K - 1u; j > 0u; --j) {
    if (pair_less(best[j], best[j - 1u])) {
      const uvec2 swap = best[j];
      best[j] = best[j - 1u];
      best[j - 1u] = swap;
    }
  }
  return true;
}

// Inserts row `frame` with `cost` unless the cost is NaN (which no
// comparison of the reference accepts, but whose key would beat an empty
// slot); `worst` follows the cost of the last kept pair (+inf while it is
// empty), for the scans' one-compare prefilter `!(cost > worst)`.
void insert_row(inout uvec2 best[K], inout float worst, float cost, uint frame) {
  if (isnan(cost)) return;
  if (insert_pair(best, uvec2(orderable_bits(cost), frame))) {
    worst = best[K - 1u].y == kNone ? uintBitsToFloat(0x7F800000u) : cost_of_key(best[K - 1u].x);
  }
}

// Keeps the row of frame (or scan row) `row` and cost `cost` among a
// query's best unless `rejected`. K = 1: (best_cost, best_row), a row of
// kNone an empty slot; when rows arrive in descending order
// (`descending`), `cost <= best_cost` keeps the lower row among equal
// costs, accepts an infinite cost into an empty slot and rejects NaN in
// one comparison, else the tie is decided by the row. K > 1: insert_row()
// behind its one-compare prefilter (a strict pair order, any arrival
// order). Branch-free for K = 1: mix() with a bool is OpSelect, and every
// operand of || and && is a named bool (glslang compiles a short-circuit
// operator whose right side is an expression into a branch).
void keep_row(inout float best_cost, inout uint best_row, inout uvec2 best[K], inout float worst, float cost, uint row,
              bool rejected, bool descending) {
  if (K == 1u) {
    const bool cheaper = descending ? cost <= best_cost : cost < best_cost;
    const bool tie_lower = !descending && cost == best_cost && row < best_row;
    const bool better = !rejected && (cheaper || tie_lower);
    best_cost = mix(best_cost, cost, better);
    best_row = mix(best_row, row, better);
  } else if (!rejected && !(cost > worst)) {
    // Rare once good rows were seen (but lavapipe masks, not skips, it).
    insert_row(best, worst, cost, row);
  }
}

#endif
