/* source.cpp - frames from a device, a video file or a folder of images
 * (source.hpp). */
#include "source.hpp"

#include <algorithm>
#include <cctype>
#include <exception>
#include <filesystem>
#include <system_error>

#include <fnmatch.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace spvscam {

namespace {

bool is_image_name(const std::string &name)
{
    static const char *const exts[] = { ".png", ".jpg", ".jpeg", ".pgm",
                                        ".ppm", ".bmp", ".tif", ".tiff" };
    std::string low = name;
    std::transform(low.begin(), low.end(), low.begin(),
                   [](unsigned char c) { return (char)std::tolower(c); });
    for (const char *e : exts) {
        const std::string ext(e);
        if (low.size() > ext.size() &&
            low.compare(low.size() - ext.size(), ext.size(), ext) == 0) {
            return true;
        }
    }
    return false;
}

} // namespace

void to_grey8(const cv::Mat &in, cv::Mat &out)
{
    cv::Mat g;
    if (in.channels() == 3) {
        cv::cvtColor(in, g, cv::COLOR_BGR2GRAY);
    } else if (in.channels() == 4) {
        cv::cvtColor(in, g, cv::COLOR_BGRA2GRAY);
    } else {
        g = in;
    }
    if (g.depth() == CV_16U) {
        g.convertTo(out, CV_8U, 1.0 / 257.0);
    } else if (g.depth() != CV_8U) {
        cv::normalize(g, out, 0, 255, cv::NORM_MINMAX, CV_8U);
    } else {
        out = g;
    }
}

std::string FrameSource::open(const std::string &spec)
{
    namespace fs = std::filesystem;
    std::error_code ec;
    /* A pattern in the file name (DIR/frame_*.png): the folder's files
     * that match it. */
    std::string dir = spec, pattern;
    const fs::path sp(spec);
    if (sp.filename().string().find_first_of("*?[") != std::string::npos) {
        dir = sp.has_parent_path() ? sp.parent_path().string() : ".";
        pattern = sp.filename().string();
    }
    if (fs::is_directory(dir, ec)) {
        kind_ = FOLDER;
        for (const fs::directory_entry &e : fs::directory_iterator(dir, ec)) {
            const std::string name = e.path().filename().string();
            if (!pattern.empty() &&
                fnmatch(pattern.c_str(), name.c_str(), 0) != 0) {
                continue;
            }
            if (is_image_name(name) && e.is_regular_file(ec)) {
                files_.push_back(e.path().string());
            }
        }
        if (ec) {
            return "cannot list the folder '" + dir + "': " + ec.message();
        }
        std::sort(files_.begin(), files_.end());
        if (files_.empty()) {
            return "the folder '" + spec + "' holds no image files";
        }
        return "";
    }
    const bool device = spec.rfind("/dev/video", 0) == 0;
    if (!device && !fs::exists(spec, ec)) {
        return "no such file, folder or device '" + spec + "'";
    }
    try {
        if (device) {
            kind_ = DEVICE;
            cap_.open(spec, cv::CAP_V4L2);
        } else {
            kind_ = VIDEO;
            cap_.open(spec);
        }
    } catch (const std::exception &e) {
        return "cannot open '" + spec + "': " + e.what();
    }
    if (!cap_.isOpened()) {
        return "cannot open '" + spec + "' as a " +
               (device ? "camera device" : "video file");
    }
    fps_ = cap_.get(cv::CAP_PROP_FPS);
    if (!(fps_ > 0.0 && fps_ < 1000.0)) {
        fps_ = 0.0;
    }
    return "";
}

FrameSource::Result FrameSource::next(cv::Mat &img, std::string &name)
{
    name.clear();
    if (kind_ == FOLDER) {
        if (next_file_ >= files_.size()) {
            return END;
        }
        const std::string &path = files_[next_file_++];
        name = std::filesystem::path(path).filename().string();
        cv::Mat raw;
        try {
            raw = cv::imread(path, cv::IMREAD_UNCHANGED);
        } catch (const std::exception &) {
            raw.release();
        }
        if (raw.empty()) {
            return UNREADABLE;
        }
        to_grey8(raw, img);
        return FRAME;
    }
    cv::Mat raw;
    bool ok = false;
    try {
        ok = cap_.read(raw);
    } catch (const std::exception &) {
        ok = false;
    }
    if (ok && !raw.empty()) {
        failures_ = 0;
        to_grey8(raw, img);
        return FRAME;
    }
    if (kind_ == VIDEO) {
        return END;
    }
    /* A device that gives nothing for kMaxDeviceFailures reads in a row
     * is gone (unplugged, its driver stopped): the run ends there. */
    if (++failures_ >= kMaxDeviceFailures) {
        return END;
    }
    return FAILED;
}

} // namespace spvscam
