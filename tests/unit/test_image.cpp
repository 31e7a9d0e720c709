// Image I/O: exact PFM round trips, PPM through sRGB, clamping, atomic output files, and
// InputErrors for unreadable, truncated or garbage files.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>

#include "errors.h"
#include "image.h"

namespace fs = std::filesystem;

namespace {

// A fresh empty directory per test, removed afterwards.
class TempDir {
public:
    TempDir() {
        std::string templ = (fs::temp_directory_path() / "rt-unit-XXXXXX").string();
        if (!mkdtemp(&templ[0])) throw std::runtime_error("mkdtemp failed");
        path_ = templ;
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path_, ec);
    }
    std::string file(const std::string& name) const { return (path_ / name).string(); }
    int entries() const {
        int n = 0;
        for (auto it = fs::directory_iterator(path_); it != fs::directory_iterator(); ++it) ++n;
        return n;
    }
    const fs::path& path() const { return path_; }

private:
    fs::path path_;
};

void write_bytes(const std::string& path, const std::string& bytes) {
    std::ofstream out(path, std::ios::binary);
    out << bytes;
}

Image random_image(int w, int h, unsigned seed) {
    std::mt19937 gen(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    Image img(w, h);
    for (Vec3& p : img.pixels) p = {u(gen), u(gen) * 3.0f, u(gen) * 1e-3f};
    return img;
}

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

template <class F>
void expect_input_error(F f, const std::string& must_contain) {
    try {
        f();
        ADD_FAILURE() << "no InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(must_contain), std::string::npos) << e.what();
    } catch (const std::exception& e) {
        ADD_FAILURE() << "not an InputError: " << e.what();
    }
}

}  // namespace

TEST(Image, AtAddressesRowMajorTopFirst) {
    Image img(3, 2);
    img.at(2, 1) = Vec3(7.0f);
    EXPECT_EQ(img.pixels[5].x, 7.0f);
    img.at(0, 1) = Vec3(5.0f);
    EXPECT_EQ(img.pixels[3].x, 5.0f);
}

TEST(Image, EncodeSrgb8) {
    EXPECT_EQ(encode_srgb8(0.0f), 0);
    EXPECT_EQ(encode_srgb8(1.0f), 255);
    EXPECT_EQ(encode_srgb8(0.5f), 188);           // the familiar sRGB mid-grey code
    EXPECT_EQ(encode_srgb8(0.0031308f * 0.5f), 5);  // linear segment: 12.92 * x * 255 = 5.16
    EXPECT_EQ(encode_srgb8(0.18f), 118);
    // Clamping.
    EXPECT_EQ(encode_srgb8(-1.0f), 0);
    EXPECT_EQ(encode_srgb8(-0.0f), 0);
    EXPECT_EQ(encode_srgb8(1.5f), 255);
    EXPECT_EQ(encode_srgb8(1e30f), 255);
    EXPECT_EQ(encode_srgb8(std::numeric_limits<float>::infinity()), 255);
    EXPECT_EQ(encode_srgb8(-std::numeric_limits<float>::infinity()), 0);
    EXPECT_EQ(encode_srgb8(std::numeric_limits<float>::quiet_NaN()), 0);
    EXPECT_EQ(encode_srgb8(-std::numeric_limits<float>::quiet_NaN()), 0);
    // Monotone over [0, 1].
    int previous = 0;
    for (int i = 0; i <= 10000; ++i) {
        const int code = encode_srgb8(i / 10000.0f);
        ASSERT_GE(code, previous);
        previous = code;
    }
    EXPECT_EQ(previous, 255);
}

TEST(Image, PfmRoundTripIsExactIncludingNonSquareSizes) {
    TempDir dir;
    for (auto [w, h] :
         {std::pair{1, 1}, std::pair{7, 3}, std::pair{3, 7}, std::pair{64, 1}, std::pair{1, 33}}) {
        Image img = random_image(w, h, w * 100 + h);
        // Values a lossy path would change: tiny, huge, negative, non-finite.
        img.at(0, 0) = {1e-38f, 3.0e38f, -2.5f};
        if (w * h > 1) img.at(w - 1, h - 1) = {std::numeric_limits<float>::infinity(), 0.1f, -0.0f};
        const std::string path = dir.file("img.pfm");
        write_pfm(path, img);
        const Image back = read_pfm(path);
        ASSERT_EQ(back.width, w);
        ASSERT_EQ(back.height, h);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const Vec3 a = img.at(x, y), b = back.at(x, y);
                ASSERT_TRUE(same_bits(a.x, b.x) && same_bits(a.y, b.y) && same_bits(a.z, b.z))
                    << w << "x" << h << " at " << x << "," << y;
            }
    }
}

TEST(Image, PfmLayoutIsBottomRowFirstLittleEndian) {
    Image img(2, 2);
    img.at(0, 0) = {1, 2, 3};  // top left
    img.at(0, 1) = {4, 5, 6};  // bottom left
    const std::string bytes = pfm_bytes(img);
    const std::string header = "PF\n2 2\n-1.0\n";
    ASSERT_EQ(bytes.substr(0, header.size()), header);
    ASSERT_EQ(bytes.size(), header.size() + 4 * 3 * 4);
    float first[3];
    std::memcpy(first, bytes.data() + header.size(), sizeof first);
    EXPECT_EQ(first[0], 4.0f);  // the bottom row comes first
    EXPECT_EQ(first[2], 6.0f);
}

TEST(Image, PpmRoundTripWithinOneCode) {
    TempDir dir;
    Image img = random_image(13, 5, 9);
    for (Vec3& p : img.pixels) p.y = std::fmin(p.y, 1.0f);
    img.at(0, 0) = {-1.0f, 2.0f, std::numeric_limits<float>::quiet_NaN()};
    const std::string path = dir.file("img.ppm");
    write_ppm(path, img);
    const Image back = read_ppm(path);
    ASSERT_EQ(back.width, 13);
    ASSERT_EQ(back.height, 5);
    for (int y = 0; y < 5; ++y)
        for (int x = 0; x < 13; ++x) {
            const Vec3 a = img.at(x, y), b = back.at(x, y);
            for (int c = 0; c < 3; ++c) {
                ASSERT_LE(std::abs(int(encode_srgb8(a[c])) - int(encode_srgb8(b[c]))), 1)
                    << x << "," << y << " channel " << c;
                ASSERT_GE(b[c], 0.0f);
                ASSERT_LE(b[c], 1.0f);
            }
        }
    EXPECT_EQ(back.at(0, 0).x, 0.0f);
    EXPECT_EQ(back.at(0, 0).y, 1.0f);
    EXPECT_EQ(back.at(0, 0).z, 0.0f);
    // The header is plain P6 with maxval 255.
    EXPECT_EQ(ppm_bytes(img).substr(0, 14),
              "P6\n13 5\n255\n" + std::string(1, char(0)) + char(255));
}

TEST(Image, AtomicFileUnwritablePathThrowsAtConstruction) {
    expect_input_error([] { AtomicFile f("/nonexistent/dir/x.pfm"); }, "/nonexistent/dir/x.pfm");
    expect_input_error([] { write_pfm("/nonexistent/dir/x.pfm", Image(1, 1)); }, "x.pfm");
}

// An existing directory is an unusable output path: it must fail when the file is opened
// (before the render), not at commit (after it).
TEST(Image, AtomicFileTargetIsADirectoryFailsAtConstruction) {
    TempDir dir;
    fs::create_directory(dir.path() / "out.ppm");
    expect_input_error([&] { AtomicFile f(dir.file("out.ppm")); }, "out.ppm");
    EXPECT_EQ(dir.entries(), 1);  // only the directory, no temporary left behind
}

TEST(Image, AtomicFileReadOnlyDirectory) {
    if (geteuid() == 0) GTEST_SKIP() << "root can write anywhere";
    TempDir dir;
    ASSERT_EQ(chmod(dir.path().c_str(), 0555), 0);
    expect_input_error([&] { AtomicFile f(dir.file("out.ppm")); }, "out.ppm");
    chmod(dir.path().c_str(), 0755);
    EXPECT_EQ(dir.entries(), 0);
}

TEST(Image, AtomicFileLeavesNothingWhenNotCommitted) {
    TempDir dir;
    {
        AtomicFile f(dir.file("out.pfm"));
        EXPECT_EQ(f.path(), dir.file("out.pfm"));
        EXPECT_EQ(dir.entries(), 1);  // the temporary exists while open
        EXPECT_FALSE(fs::exists(dir.file("out.pfm")));
    }
    EXPECT_EQ(dir.entries(), 0);
    // Nor when an exception unwinds past it (a render that fails half way).
    try {
        AtomicFile f(dir.file("out.pfm"));
        throw std::runtime_error("render failed");
    } catch (const std::runtime_error&) {
    }
    EXPECT_EQ(dir.entries(), 0);
}

TEST(Image, AtomicFileCommitReplacesTargetWhole) {
    TempDir dir;
    const std::string path = dir.file("out.ppm");
    write_bytes(path, "old contents");
    {
        AtomicFile f(path);
        // Until commit the old file is untouched.
        std::ifstream in(path);
        std::string old((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        EXPECT_EQ(old, "old contents");
        f.commit("new");
    }
    std::ifstream in(path);
    std::string now((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(now, "new");
    EXPECT_EQ(dir.entries(), 1);  // no temporary left
    struct stat st;
    ASSERT_EQ(stat(path.c_str(), &st), 0);
    EXPECT_EQ(st.st_mode & 0777, 0644u);
}

TEST(Image, ReadMissingFileThrows) {
    TempDir dir;
    expect_input_error([&] { read_pfm(dir.file("missing.pfm")); }, "missing.pfm");
    expect_input_error([&] { read_ppm(dir.file("missing.ppm")); }, "missing.ppm");
}

TEST(Image, ReadTruncatedFilesThrows) {
    TempDir dir;
    const std::string pfm = pfm_bytes(random_image(4, 3, 1));
    const std::string ppm = ppm_bytes(random_image(4, 3, 2));
    const std::string pfm_path = dir.file("t.pfm"), ppm_path = dir.file("t.ppm");
    for (size_t cut : {size_t(0), size_t(1), size_t(5), size_t(11), pfm.size() - 1}) {
        write_bytes(pfm_path, pfm.substr(0, cut));
        expect_input_error([&] { read_pfm(pfm_path); }, "t.pfm");
    }
    for (size_t cut : {size_t(0), size_t(2), size_t(6), size_t(11), ppm.size() - 1}) {
        write_bytes(ppm_path, ppm.substr(0, cut));
        expect_input_error([&] { read_ppm(ppm_path); }, "t.ppm");
    }
    // Extra bytes are as wrong as missing ones.
    write_bytes(pfm_path, pfm + "x");
    expect_input_error([&] { read_pfm(pfm_path); }, "t.pfm");
}

TEST(Image, ReadGarbageThrows) {
    TempDir dir;
    const std::string path = dir.file("g.pfm");
    const char* garbage[] = {
        "hello world",
        "P6\n2 2\n255\n",                     // a PPM is not a PFM
        "Pf\n2 2\n-1.0\n",                    // greyscale PFM
        "PF\n2 2\n1.0\n"
        "xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx",  // big endian
        "PF\n0 2\n-1.0\n",                    // zero size
        "PF\n-2 2\n-1.0\n",
        "PF\nabc 2\n-1.0\n",
        "PF\n2x 2\n-1.0\n",
    };
    for (const char* g : garbage) {
        write_bytes(path, g);
        expect_input_error([&] { read_pfm(path); }, "g.pfm");
    }
    const std::string ppm_path = dir.file("g.ppm");
    for (const char* g : {"P3\n1 1\n255\n1 2 3\n", "P6\n1 1\n65535\n123456", "P6\n1 1\n"}) {
        write_bytes(ppm_path, g);
        expect_input_error([&] { read_ppm(ppm_path); }, "g.ppm");
    }
    std::mt19937 gen(3);
    std::string noise(1000, '\0');
    for (char& c : noise) c = static_cast<char>(gen());
    write_bytes(path, noise);
    expect_input_error([&] { read_pfm(path); }, "g.pfm");
}
