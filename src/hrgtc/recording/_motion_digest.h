/* The 64-bit digest of a column's bits (compensate's check of its rows).
 *
 * Part of _motion_native.c, which includes it once (one translation unit: the functions
 * are static). */
#ifndef HRGTC_MOTION_DIGEST_H
#define HRGTC_MOTION_DIGEST_H

/* ------------------------------------------------------------- the rows' digest */

/* A 64-bit digest of a column's bits, fed in pieces (compensate's check that its rows are
 * those the detector read, compensate/at_rest.py). The state: four lanes, word i going
 * into lane i % 4 by xxHash64's round (acc + w P2, rotated 31, times P1: for a fixed acc
 * a bijection of w, and for a fixed w of acc), and the count of words. So a change of one
 * word always changes the digest (each later step, the merge and the mixing are
 * bijections); more changes escape it with a chance of about 2^-64. The lanes are merged
 * by the same round, one after the other, and mixed by xxHash64's avalanche. */
#define P1 11400714785074694791ULL
#define P2 14029467366897019727ULL
#define P3 1609587929392839161ULL
#define P4 9650029242287828579ULL
#define P5 2870177450012600261ULL

static inline uint64_t rotl(uint64_t x, int r) { return (x << r) | (x >> (64 - r)); }
static inline uint64_t lane_round(uint64_t acc, uint64_t w) { return rotl(acc + w * P2, 31) * P1; }

static void digest_feed(uint64_t state[5], const uint64_t *words, idx n)
{
    uint64_t lane[4] = {state[0], state[1], state[2], state[3]};
    idx i = 0;
    uint64_t first = state[4] & 3;
    for (; i < n && ((first + (uint64_t)i) & 3); i++)  /* up to a stripe's start */
        lane[(first + (uint64_t)i) & 3] = lane_round(lane[(first + (uint64_t)i) & 3], words[i]);
    for (; i + 4 <= n; i += 4)
        for (int k = 0; k < 4; k++) lane[k] = lane_round(lane[k], words[i + k]);
    for (; i < n; i++) lane[(first + (uint64_t)i) & 3] = lane_round(lane[(first + (uint64_t)i) & 3],
                                                                words[i]);
    for (int k = 0; k < 4; k++) state[k] = lane[k];
    state[4] += (uint64_t)n;
}

static uint64_t digest_final(const uint64_t state[5])
{
    uint64_t h = P5;  /* the lanes in turn: each step a bijection of the lane and of h */
    for (int k = 0; k < 4; k++) h = lane_round(h, state[k]) + P4;
    h += state[4] * P5;
    h ^= h >> 33;
    h *= P2;
    h ^= h >> 29;
    h *= P3;
    h ^= h >> 32;
    return h;
}


#endif /* HRGTC_MOTION_DIGEST_H */
