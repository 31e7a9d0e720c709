// Counter-based random numbers: reproducible, in [0, 1), distinct streams per key, roughly
// uniform and uncorrelated between neighbouring pixels, samples and dimensions.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <set>
#include <vector>

#include "rng.h"

namespace {

// Pearson correlation of two equally long series.
double correlation(const std::vector<double>& a, const std::vector<double>& b) {
    const size_t n = a.size();
    double ma = 0, mb = 0;
    for (size_t i = 0; i < n; ++i) {
        ma += a[i];
        mb += b[i];
    }
    ma /= n;
    mb /= n;
    double sab = 0, saa = 0, sbb = 0;
    for (size_t i = 0; i < n; ++i) {
        sab += (a[i] - ma) * (b[i] - mb);
        saa += (a[i] - ma) * (a[i] - ma);
        sbb += (b[i] - mb) * (b[i] - mb);
    }
    return sab / std::sqrt(saa * sbb);
}

// Chi-square statistic of values in [0, 1) over `bins` equal bins.
double chi_square(const std::vector<double>& v, int bins) {
    std::vector<long> count(bins, 0);
    for (double x : v) ++count[static_cast<int>(x * bins)];
    const double expected = static_cast<double>(v.size()) / bins;
    double chi2 = 0;
    for (long c : count) chi2 += (c - expected) * (c - expected) / expected;
    return chi2;
}

constexpr int kN = 100000;

}  // namespace

TEST(Rng, Mix64KnownAnswer) {
    // SplitMix64 seeded with 0: the first output is mix64(golden gamma).
    EXPECT_EQ(mix64(0x9e3779b97f4a7c15ull), 0xe220a8397b1dcdafull);
    EXPECT_EQ(mix64(0), 0u);  // the finaliser maps 0 to 0 (why the key is pre-mixed)
}

TEST(Rng, Mix64IsInjectiveOnASample) {
    std::set<uint64_t> seen;
    for (uint64_t i = 0; i < 20000; ++i) seen.insert(mix64(i));
    EXPECT_EQ(seen.size(), 20000u);
}

TEST(Rng, Mix64AvalanchesEachInputBit) {
    // Flipping any one input bit flips about half the output bits, on average.
    for (int bit = 0; bit < 64; ++bit) {
        double flipped = 0;
        const int n = 200;
        for (uint64_t i = 1; i <= n; ++i) {
            const uint64_t x = mix64(i * 0x2545F4914F6CDD1Dull);
            flipped += __builtin_popcountll(mix64(x) ^ mix64(x ^ (1ull << bit)));
        }
        EXPECT_NEAR(flipped / n, 32.0, 2.0) << "bit " << bit;
    }
}

TEST(Rng, UnitFloatRange) {
    EXPECT_EQ(unit_float(0), 0.0f);
    EXPECT_LT(unit_float(~0ull), 1.0f);
    EXPECT_EQ(unit_float(~0ull), 1.0f - 1.0f / 16777216.0f);
    EXPECT_EQ(unit_float(1ull << 63), 0.5f);
    EXPECT_EQ(unit_float((1ull << 40) - 1), 0.0f);  // the low 40 bits are dropped
    EXPECT_EQ(unit_float(1ull << 40), 1.0f / 16777216.0f);
}

TEST(Rng, ValuesInHalfOpenUnitInterval) {
    float lo = 1, hi = 0;
    for (uint64_t p = 0; p < 1000; ++p) {
        const SampleStream s(42, p, 3);
        for (uint32_t d = 0; d < 100; ++d) {
            const float v = s.at(d);
            ASSERT_GE(v, 0.0f);
            ASSERT_LT(v, 1.0f);
            lo = std::fmin(lo, v);
            hi = std::fmax(hi, v);
        }
    }
    EXPECT_LT(lo, 1e-4f);
    EXPECT_GT(hi, 1.0f - 1e-4f);
}

TEST(Rng, Reproducible) {
    for (uint64_t seed : {0ull, 1ull, 123456789ull, ~0ull}) {
        const SampleStream a(seed, 77, 5), b(seed, 77, 5);
        for (uint32_t d = 0; d < 64; ++d) EXPECT_EQ(a.at(d), b.at(d));
    }
    // A stream is a value, not a generator: reading does not advance it.
    const SampleStream s(0, 0, 0);
    const float first = s.at(0);
    for (uint32_t d = 1; d < 10; ++d) (void)s.at(d);
    EXPECT_EQ(s.at(0), first);
    EXPECT_NE(s.at(0), s.at(1));
}

TEST(Rng, DistinctStreamsForDistinctKeys) {
    // The first 4 dimensions as one 96-bit fingerprint; every key must give its own.
    auto fingerprint = [](const SampleStream& s) {
        std::vector<float> v;
        for (uint32_t d = 0; d < 4; ++d) v.push_back(s.at(d));
        return v;
    };
    std::set<std::vector<float>> seen;
    int streams = 0;
    for (uint64_t seed = 0; seed < 4; ++seed)
        for (uint64_t pixel = 0; pixel < 100; ++pixel)
            for (uint64_t sample = 0; sample < 50; ++sample) {
                seen.insert(fingerprint(SampleStream(seed, pixel, sample)));
                ++streams;
            }
    EXPECT_EQ(seen.size(), static_cast<size_t>(streams));
    // Swapping the roles of pixel and sample must not give the same stream.
    int same = 0;
    for (uint64_t a = 0; a < 50; ++a)
        for (uint64_t b = 0; b < 50; ++b)
            if (a != b && SampleStream(0, a, b).at(0) == SampleStream(0, b, a).at(0)) ++same;
    EXPECT_LT(same, 3);
    // Seeds that differ only in high bits (the CLI takes seeds up to 2^53).
    EXPECT_NE(SampleStream(1ull << 52, 0, 0).at(0), SampleStream(0, 0, 0).at(0));
    EXPECT_NE(SampleStream(0, 1ull << 40, 0).at(0), SampleStream(0, 0, 0).at(0));
}

TEST(Rng, DimensionsDiffer) {
    const SampleStream s(5, 6, 7);
    std::set<float> seen;
    for (uint32_t d = 0; d < 1000; ++d) seen.insert(s.at(d));
    EXPECT_GT(seen.size(), 990u);  // 24-bit values: a handful of collisions at most
}

TEST(Rng, UniformChiSquare) {
    // 1e5 values over 100 bins: chi-square with 99 degrees of freedom has mean 99 and
    // standard deviation 14; 200 is > 7 sigma. Checked along every key direction.
    std::vector<double> by_pixel, by_sample, by_dim, by_seed;
    for (int i = 0; i < kN; ++i) {
        by_pixel.push_back(SampleStream(0, i, 0).at(0));
        by_sample.push_back(SampleStream(0, 0, i).at(2));
        by_dim.push_back(SampleStream(1, 2, 3).at(static_cast<uint32_t>(i)));
        by_seed.push_back(SampleStream(i, 9, 9).at(1));
    }
    EXPECT_LT(chi_square(by_pixel, 100), 200);
    EXPECT_LT(chi_square(by_sample, 100), 200);
    EXPECT_LT(chi_square(by_dim, 100), 200);
    EXPECT_LT(chi_square(by_seed, 100), 200);
    // And not suspiciously perfect either (a counter, not random numbers, would give ~0).
    EXPECT_GT(chi_square(by_pixel, 100), 40);
    EXPECT_GT(chi_square(by_dim, 100), 40);
}

TEST(Rng, MeanAndVarianceOfUniform) {
    double sum = 0, sum2 = 0;
    for (int i = 0; i < kN; ++i) {
        const double v = SampleStream(3, i, i % 7).at(i % 5);
        sum += v;
        sum2 += v * v;
    }
    const double mean = sum / kN, var = sum2 / kN - mean * mean;
    EXPECT_NEAR(mean, 0.5, 0.005);       // standard error 0.0009
    EXPECT_NEAR(var, 1.0 / 12.0, 0.002);  // standard error 0.0002
}

TEST(Rng, NeighbouringPixelsUncorrelated) {
    std::vector<double> a, b;
    for (int i = 0; i < kN; ++i) {
        a.push_back(SampleStream(0, i, 0).at(0));
        b.push_back(SampleStream(0, i + 1, 0).at(0));
    }
    EXPECT_LT(std::fabs(correlation(a, b)), 0.01);
}

TEST(Rng, NeighbouringSamplesUncorrelated) {
    std::vector<double> a, b;
    for (int i = 0; i < kN; ++i) {
        a.push_back(SampleStream(7, 1234, i).at(3));
        b.push_back(SampleStream(7, 1234, i + 1).at(3));
    }
    EXPECT_LT(std::fabs(correlation(a, b)), 0.01);
}

TEST(Rng, NeighbouringDimensionsUncorrelated) {
    std::vector<double> a, b, c;
    for (int i = 0; i < kN; ++i) {
        const SampleStream s(0, i, 0);
        a.push_back(s.at(0));
        b.push_back(s.at(1));
        c.push_back(s.at(2));
    }
    EXPECT_LT(std::fabs(correlation(a, b)), 0.01);
    EXPECT_LT(std::fabs(correlation(b, c)), 0.01);
    EXPECT_LT(std::fabs(correlation(a, c)), 0.01);
}

TEST(Rng, NeighbouringSeedsUncorrelated) {
    std::vector<double> a, b;
    for (int i = 0; i < kN; ++i) {
        a.push_back(SampleStream(0, i, 0).at(2));
        b.push_back(SampleStream(1, i, 0).at(2));
    }
    EXPECT_LT(std::fabs(correlation(a, b)), 0.01);
}

TEST(Rng, PairsAreUniformInTheSquare) {
    // (dim 0, dim 1) pairs, the pixel jitter, over a 10 x 10 grid: 99 dof.
    std::vector<long> count(100, 0);
    for (int i = 0; i < kN; ++i) {
        const SampleStream s(0, i, 0);
        ++count[static_cast<int>(s.at(kDimPixelX) * 10) * 10 +
                static_cast<int>(s.at(kDimPixelY) * 10)];
    }
    double chi2 = 0;
    for (long c : count) chi2 += (c - 1000.0) * (c - 1000.0) / 1000.0;
    EXPECT_LT(chi2, 200);
}

TEST(Rng, BounceDimensionsAreDistinctAndAfterThePixelJitter) {
    std::set<uint32_t> dims{kDimPixelX, kDimPixelY};
    for (int bounce = 0; bounce < 64; ++bounce)
        for (uint32_t k = 0; k < kDimsPerBounce; ++k)
            EXPECT_TRUE(dims.insert(bounce_dimension(bounce, k)).second)
                << "bounce " << bounce << " k " << k;
    EXPECT_EQ(bounce_dimension(0, 0), 2u);
}
