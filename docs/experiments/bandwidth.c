/* What one core reads and writes a second from an array of a given size: the measure behind
 * docs/performance.md, "Gravity's length once a step, and where a million balls lose".
 *
 *   cc -O2 docs/experiments/bandwidth.c -o /tmp/bandwidth
 *   taskset -c 1 /tmp/bandwidth 24     # a million balls' circles (24 B each): in the cache
 *   taskset -c 1 /tmp/bandwidth 400    # a million balls' whole step: from memory
 *
 * Each of five rounds reads the array of MiB given (doubles, in four running sums), then reads
 * it again as "circles" of three doubles and writes a 4-B "cell" for each, as the grid's cell
 * pass does. The first rounds warm the array up; the last ones are the figure. */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static double seconds(void) {
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    return now.tv_sec + now.tv_nsec * 1e-9;
}

int main(int argc, char **argv) {
    size_t mib = argc > 1 ? (size_t)atoi(argv[1]) : 24;
    size_t count = mib * 1024 * 1024 / sizeof(double);
    double *values = malloc(count * sizeof(double));
    unsigned *cells = malloc(count / 3 * sizeof(unsigned));
    if (!values || !cells) return 1;
    for (size_t i = 0; i < count; i++) values[i] = i * 0.5;
    for (int round = 0; round < 5; round++) {
        double start = seconds(), sums[4] = {0, 0, 0, 0};
        for (size_t i = 0; i + 3 < count; i += 4)
            for (int lane = 0; lane < 4; lane++) sums[lane] += values[i + lane];
        double read = seconds();
        for (size_t i = 0; i < count / 3; i++)
            cells[i] = (unsigned)(values[3 * i] * 0.03) + (unsigned)(values[3 * i + 1] * 0.03) * 300;
        double written = seconds();
        printf("%zu MiB: read %.1f GB/s, read and write the cells %.1f GB/s (%g)\n", mib,
               count * sizeof(double) / (read - start) / 1e9,
               (count * sizeof(double) + count / 3 * sizeof(unsigned)) / (written - read) / 1e9,
               sums[0] + sums[1] + sums[2] + sums[3] + cells[count / 6]);
    }
    return 0;
}
