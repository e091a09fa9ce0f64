// How many threads the core may keep busy at once. Natively the core overlaps independent stages
// on a second thread (the transfer's cage and mean-value coordinates beside the eigenbases, the
// editor's Poisson factor beside the Eq. 7 factor); the results are bit-identical whatever the
// count (each stage does the same arithmetic on either thread). WebAssembly is built without
// threads: 1 there.
#pragma once

namespace mm {

// Default: MM_THREADS from the environment when it is a positive integer, else the hardware's
// concurrency (at least 1).
int max_threads();
// n ≥ 1 overrides the default (the bench's --threads); n ≤ 0 goes back to it. Not meant to be
// changed while a computation runs.
void set_max_threads(int n);

}  // namespace mm
