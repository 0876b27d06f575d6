/* camera_make_video.cpp - writes images (in the order given) into an
 * MJPEG AVI with OpenCV's own writer, for spvs-camera's video-file test.
 * usage: camera_make_video OUT.avi FPS IMAGE... ; exit 0, or 1 with a
 * one-line reason. */
#include <cstdio>
#include <cstdlib>
#include <exception>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

int main(int argc, char **argv)
{
    if (argc < 4) {
        std::fprintf(stderr, "usage: camera_make_video OUT.avi FPS IMAGE...\n");
        return 2;
    }
    try {
        cv::VideoWriter out;
        for (int i = 3; i < argc; ++i) {
            cv::Mat img = cv::imread(argv[i], cv::IMREAD_COLOR);
            if (img.empty()) {
                std::fprintf(stderr, "camera_make_video: cannot read '%s'\n", argv[i]);
                return 1;
            }
            if (!out.isOpened() &&
                !out.open(argv[1], cv::CAP_OPENCV_MJPEG,
                          cv::VideoWriter::fourcc('M', 'J', 'P', 'G'),
                          std::atof(argv[2]), img.size(), true)) {
                std::fprintf(stderr, "camera_make_video: cannot write '%s'\n", argv[1]);
                return 1;
            }
            out.write(img);
        }
    } catch (const std::exception &e) {
        std::fprintf(stderr, "camera_make_video: %s\n", e.what());
        return 1;
    }
    return 0;
}
