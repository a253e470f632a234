/* tightknot: a seeded random stream (private to engine/).  splitmix64:
 * the whole state is one 64-bit word, so a run, a projection or a
 * generator owns its own stream and a seed reproduces it on any machine
 * and in any thread. */
#ifndef TK_ENGINE_RNG_H
#define TK_ENGINE_RNG_H

#include <math.h>
#include <stdint.h>

static inline uint64_t tk_rng_next(uint64_t *s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

/* Uniform in [0, 1), 53 bits. */
static inline double tk_rng_uniform(uint64_t *s)
{
    return (double)(tk_rng_next(s) >> 11) / 9007199254740992.0;
}

/* Standard normal (Box-Muller; one draw per call, the other discarded
 * so that the stream's position depends only on the number of calls). */
static inline double tk_rng_normal(uint64_t *s)
{
    double u = 1.0 - tk_rng_uniform(s); /* (0, 1] */
    double v = tk_rng_uniform(s);
    return sqrt(-2.0 * log(u)) * cos(2.0 * M_PI * v);
}

/* A direction uniform on the unit sphere. */
static inline void tk_rng_direction(uint64_t *s, double d[3])
{
    double z = 2.0 * tk_rng_uniform(s) - 1.0;
    double r = sqrt(fmax(0.0, 1.0 - z * z)), phi = 2.0 * M_PI * tk_rng_uniform(s);
    d[0] = r * cos(phi);
    d[1] = r * sin(phi);
    d[2] = z;
}

#endif
