// Round trip of a cache line between two threads pinned to cpu 0 and cpu 1, ns.
#define _GNU_SOURCE
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdio.h>
#include <time.h>
static _Atomic long flag __attribute__((aligned(64)));
static const long N = 200000;
static void pin(int cpu) { cpu_set_t s; CPU_ZERO(&s); CPU_SET(cpu, &s); pthread_setaffinity_np(pthread_self(), sizeof s, &s); }
static void *other(void *arg) { (void)arg; pin(1); for (long i = 0; i < N; i++) { while (atomic_load_explicit(&flag, memory_order_acquire) != 2*i+1) ; atomic_store_explicit(&flag, 2*i+2, memory_order_release);} return 0; }
int main(void) {
  pin(0); pthread_t t; pthread_create(&t, 0, other, 0);
  struct timespec a, b; clock_gettime(CLOCK_MONOTONIC, &a);
  for (long i = 0; i < N; i++) { atomic_store_explicit(&flag, 2*i+1, memory_order_release); while (atomic_load_explicit(&flag, memory_order_acquire) != 2*i+2) ; }
  clock_gettime(CLOCK_MONOTONIC, &b); pthread_join(t, 0);
  printf("%.1f\n", ((b.tv_sec-a.tv_sec)*1e9 + (b.tv_nsec-a.tv_nsec)) / N);
}
