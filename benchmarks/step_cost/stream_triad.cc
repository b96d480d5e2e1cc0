// The memory-bandwidth floor of this machine (issue 14, item 2): the
// STREAM triad a = b + s c on arrays far larger than the caches, one
// thread, best of 10 repetitions; prints GB/s counting 24 bytes per entry
// (two reads and one write; the write-allocate read is not counted, as in
// STREAM).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

int main()
{
  const std::size_t   n = 1 << 25; // 3 x 256 MB
  std::vector<double> a(n, 0.), b(n, 1.), c(n, 2.);
  double              best = 1e30;
  for (int r = 0; r < 10; ++r)
    {
      const auto start = std::chrono::steady_clock::now();
      for (std::size_t i = 0; i < n; ++i)
        a[i] = b[i] + 3. * c[i];
      const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      best = std::min(best, t);
    }
  std::printf("%.2f GB/s (triad, one thread; check %.1f)\n", 24. * n / best / 1e9, a[n / 2]);
  return 0;
}
