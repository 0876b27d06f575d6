/*
 * source.hpp - where spvs-camera's frames come from: a V4L2 device
 * (/dev/videoN), a video file, or a folder of images read in name order.
 * Frames come out as 8-bit grey images; a frame that cannot be read is
 * told apart from the end of the source and from a lost device.
 */
#ifndef SPVS_CAMERA_SOURCE_HPP
#define SPVS_CAMERA_SOURCE_HPP

#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

namespace spvscam {

class FrameSource {
public:
    enum Kind { FOLDER, VIDEO, DEVICE };
    enum Result {
        FRAME,       /* img holds the frame                                */
        UNREADABLE,  /* a file of the folder that is no image              */
        FAILED,      /* the device gave no frame this time                 */
        END          /* the source ended (or the device is lost)           */
    };

    /* Opens spec: a folder (its image files, or those matching a pattern
     * in the last part of spec, DIR/frame_*.png:: .png .jpg .jpeg .pgm .ppm
     * .bmp .tif .tiff, in name order), a /dev/video* device, or anything
     * else as a video file.  Returns "" or a one-line reason. */
    std::string open(const std::string &spec);

    /* The next frame, grey.  name: the file's name (folder) or "". */
    Result next(cv::Mat &img, std::string &name);

    Kind kind() const { return kind_; }
    /* Frames per second the video or device reports (0: unknown). */
    double fps() const { return fps_; }

    /* Consecutive failed reads after which a device counts as lost. */
    static constexpr int kMaxDeviceFailures = 30;

private:
    Kind kind_ = FOLDER;
    std::vector<std::string> files_;
    size_t next_file_ = 0;
    cv::VideoCapture cap_;
    int failures_ = 0;
    double fps_ = 0.0;
};

/* Grey 8-bit copy of any image OpenCV reads (colour, 16-bit). */
void to_grey8(const cv::Mat &in, cv::Mat &out);

} // namespace spvscam

#endif /* SPVS_CAMERA_SOURCE_HPP */
