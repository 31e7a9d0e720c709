// Linear-radiance image buffer and its file formats: PFM (float32, lossless, what tests
// compare) and PPM P6 (8-bit sRGB, for looking at).
#pragma once

#include <string>
#include <vector>

#include <vec3.h>

struct Image {
    int width = 0;
    int height = 0;
    std::vector<Vec3> pixels;  // row-major, top row first

    Image() = default;
    Image(int w, int h) : width(w), height(h), pixels(static_cast<size_t>(w) * h) {}

    Vec3& at(int x, int y) { return pixels[static_cast<size_t>(y) * width + x]; }
    const Vec3& at(int x, int y) const { return pixels[static_cast<size_t>(y) * width + x]; }
};

// sRGB transfer function of one linear value, clamped to [0, 1], as an 8-bit code.
unsigned char encode_srgb8(float linear);

// Serialised file contents; writing goes through AtomicFile so no half-written file is left.
std::string ppm_bytes(const Image& image);
std::string pfm_bytes(const Image& image);

// Readers; throw InputError naming the file and what was wrong.
Image read_pfm(const std::string& path);
Image read_ppm(const std::string& path);  // decodes sRGB back to linear

// An output file that appears whole or not at all: the bytes go to a temporary file beside
// the target, which replaces the target only on commit(). Opening it checks that the path
// is writable, so a bad --out fails before a long render, not after.
class AtomicFile {
public:
    explicit AtomicFile(std::string path);  // throws InputError if it cannot be created
    ~AtomicFile();                          // removes the temporary if not committed
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;

    void commit(const std::string& bytes);  // write, flush, rename over the target

    const std::string& path() const { return path_; }

private:
    std::string path_;       // the target
    std::string temp_path_;  // where the bytes go first
    int fd_ = -1;            // open temporary, or -1 once committed
};

// Convenience for tests and tools: write a file atomically in one call.
void write_pfm(const std::string& path, const Image& image);
void write_ppm(const std::string& path, const Image& image);
