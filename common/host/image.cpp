#include <image.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include <errors.h>
#include <interrupt_cleanup.h>

unsigned char encode_srgb8(float linear) {
    const float c = std::isnan(linear) ? 0.0f : std::fmin(std::fmax(linear, 0.0f), 1.0f);
    const float encoded = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
    return static_cast<unsigned char>(std::lround(encoded * 255.0f));
}

static float decode_srgb8(unsigned char code) {
    const float c = code / 255.0f;
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

std::string ppm_bytes(const Image& image) {
    std::string out =
        "P6\n" + std::to_string(image.width) + " " + std::to_string(image.height) + "\n255\n";
    out.reserve(out.size() + image.pixels.size() * 3);
    for (const Vec3& p : image.pixels) {
        out.push_back(static_cast<char>(encode_srgb8(p.x)));
        out.push_back(static_cast<char>(encode_srgb8(p.y)));
        out.push_back(static_cast<char>(encode_srgb8(p.z)));
    }
    return out;
}

// PFM: "PF", size, then a scale whose sign gives the byte order (negative: little endian);
// rows are stored bottom to top.
std::string pfm_bytes(const Image& image) {
    std::string out =
        "PF\n" + std::to_string(image.width) + " " + std::to_string(image.height) + "\n-1.0\n";
    const size_t header = out.size();
    out.resize(header + image.pixels.size() * 3 * sizeof(float));
    char* dst = &out[header];
    for (int y = image.height - 1; y >= 0; --y) {
        for (int x = 0; x < image.width; ++x) {
            const Vec3& p = image.at(x, y);
            // Written as float in either build (real.h): the double build's pixels round here.
            const float rgb[3] = {static_cast<float>(p.x), static_cast<float>(p.y),
                                  static_cast<float>(p.z)};
            std::memcpy(dst, rgb, sizeof rgb);  // x86 and CUDA hosts are little endian
            dst += sizeof rgb;
        }
    }
    return out;
}

static std::string read_whole_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path + ": cannot open for reading: " + std::strerror(errno));
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// Reads the whitespace-separated header tokens of a Netpbm-style file.
static std::string next_token(const std::string& path, const std::string& data, size_t& pos) {
    while (pos < data.size() && std::isspace(static_cast<unsigned char>(data[pos]))) ++pos;
    const size_t start = pos;
    while (pos < data.size() && !std::isspace(static_cast<unsigned char>(data[pos]))) ++pos;
    if (start == pos) throw InputError(path + ": truncated header");
    return data.substr(start, pos - start);
}

static int parse_dimension(const std::string& path, const std::string& token) {
    char* end = nullptr;
    const long v = std::strtol(token.c_str(), &end, 10);
    if (*end != '\0' || v <= 0 || v > 65536)
        throw InputError(path + ": expected an image size in 1..65536, found '" + token + "'");
    return static_cast<int>(v);
}

Image read_pfm(const std::string& path) {
    const std::string data = read_whole_file(path);
    size_t pos = 0;
    if (next_token(path, data, pos) != "PF")
        throw InputError(path + ": not a colour PFM file (expected 'PF')");
    const int w = parse_dimension(path, next_token(path, data, pos));
    const int h = parse_dimension(path, next_token(path, data, pos));
    const std::string scale = next_token(path, data, pos);
    if (scale.empty() || scale[0] != '-')
        throw InputError(path + ": big-endian PFM is not supported (expected a negative scale)");
    ++pos;  // the single whitespace byte after the header
    // Check the size before allocating: a garbage header must not ask for gigabytes.
    const size_t need = static_cast<size_t>(w) * h * 3 * sizeof(float);
    if (data.size() - std::min(pos, data.size()) != need)
        throw InputError(path + ": expected " + std::to_string(need) + " bytes of pixels");
    Image image(w, h);
    const char* src = data.data() + pos;
    for (int y = h - 1; y >= 0; --y) {
        for (int x = 0; x < w; ++x) {
            float rgb[3];
            std::memcpy(rgb, src, sizeof rgb);
            src += sizeof rgb;
            image.at(x, y) = {rgb[0], rgb[1], rgb[2]};
        }
    }
    return image;
}

Image read_ppm(const std::string& path) {
    const std::string data = read_whole_file(path);
    size_t pos = 0;
    if (next_token(path, data, pos) != "P6")
        throw InputError(path + ": not a binary PPM file (expected 'P6')");
    const int w = parse_dimension(path, next_token(path, data, pos));
    const int h = parse_dimension(path, next_token(path, data, pos));
    if (next_token(path, data, pos) != "255")
        throw InputError(path + ": only 8-bit PPM (maxval 255) is supported");
    ++pos;
    const size_t need = static_cast<size_t>(w) * h * 3;
    if (data.size() - std::min(pos, data.size()) != need)
        throw InputError(path + ": expected " + std::to_string(need) + " bytes of pixels");
    Image image(w, h);
    const auto* src = reinterpret_cast<const unsigned char*>(data.data() + pos);
    for (Vec3& p : image.pixels) {
        p = {decode_srgb8(src[0]), decode_srgb8(src[1]), decode_srgb8(src[2])};
        src += 3;
    }
    return image;
}

AtomicFile::AtomicFile(std::string path) : path_(std::move(path)) {
    struct stat st;
    if (::stat(path_.c_str(), &st) == 0 && S_ISDIR(st.st_mode))
        throw InputError(path_ + ": cannot write output file: it is a directory");
    temp_path_ = path_ + ".partial-XXXXXX";
    fd_ = mkstemp(&temp_path_[0]);
    if (fd_ < 0) throw InputError(path_ + ": cannot write output file: " + std::strerror(errno));
    remove_on_interrupt(temp_path_.c_str());  // a render stopped by Ctrl-C leaves nothing
}

AtomicFile::~AtomicFile() {
    if (fd_ >= 0) {
        ::close(fd_);
        ::unlink(temp_path_.c_str());
        forget_on_interrupt(temp_path_.c_str());
    }
}

void AtomicFile::commit(const std::string& bytes) {
    size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd_, bytes.data() + done, bytes.size() - done);
        if (n < 0) {
            if (errno == EINTR) continue;
            throw InputError(path_ + ": write failed: " + std::strerror(errno));
        }
        done += static_cast<size_t>(n);
    }
    if (::fchmod(fd_, 0644) != 0)  // mkstemp makes 0600; outputs are ordinary files
        throw InputError(path_ + ": write failed: " + std::strerror(errno));
    ::close(fd_);
    fd_ = -1;
    const bool renamed = std::rename(temp_path_.c_str(), path_.c_str()) == 0;
    const int err = errno;
    forget_on_interrupt(temp_path_.c_str());
    if (!renamed) {
        ::unlink(temp_path_.c_str());
        throw InputError(path_ + ": cannot replace output file: " + std::strerror(err));
    }
}

void write_pfm(const std::string& path, const Image& image) {
    AtomicFile(path).commit(pfm_bytes(image));
}

void write_ppm(const std::string& path, const Image& image) {
    AtomicFile(path).commit(ppm_bytes(image));
}
