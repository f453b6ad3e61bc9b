// One core's streaming bandwidth: read, write, copy and a += s * b over 256-MB arrays, far
// past the L3 cache; best of 7 runs each, GB/s of the bytes each loop names (a write's
// read-for-ownership not counted).  cc -O2 docs/experiments/stream-bandwidth.c -o /tmp/stream
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#define N (32L * 1024 * 1024) /* doubles: 256 MB an array */
static double now(void) { struct timespec t; clock_gettime(CLOCK_MONOTONIC, &t); return t.tv_sec + t.tv_nsec * 1e-9; }
int main(void) {
    double *a = malloc(N * sizeof(double)), *b = malloc(N * sizeof(double));
    for (long i = 0; i < N; i++) { a[i] = i; b[i] = 2 * i; }
    double best[4] = {1e9, 1e9, 1e9, 1e9}, sink = 0;
    for (int r = 0; r < 7; r++) {
        double t = now(), s0 = 0, s1 = 0, s2 = 0, s3 = 0;
        for (long i = 0; i < N; i += 4) { s0 += a[i]; s1 += a[i + 1]; s2 += a[i + 2]; s3 += a[i + 3]; }
        sink += s0 + s1 + s2 + s3; t = now() - t; if (t < best[0]) best[0] = t;
        t = now();
        for (long i = 0; i < N; i++) a[i] = r + i;
        t = now() - t; if (t < best[1]) best[1] = t;
        t = now();
        memcpy(b, a, N * sizeof(double));
        t = now() - t; if (t < best[2]) best[2] = t;
        t = now();
        for (long i = 0; i < N; i++) a[i] += 0.5 * b[i];
        t = now() - t; if (t < best[3]) best[3] = t;
    }
    double mb = N * sizeof(double) / 1e9;
    printf("read %.1f GB/s, write %.1f GB/s, copy %.1f GB/s (read+write), a+=s*b %.1f GB/s (3 arrays' bytes)  [%g]\n",
           mb / best[0], mb / best[1], 2 * mb / best[2], 3 * mb / best[3], sink);
    return 0;
}
