/*
 * frontend_internal.hpp - pieces of the image front end shared by its
 * sources: procedural textures, the textured scene and its ray caster.
 * Not a public interface (see sim/frontend.h).
 */
#ifndef SIM_FRONTEND_INTERNAL_HPP
#define SIM_FRONTEND_INTERNAL_HPP

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "sim/geometry.h"

namespace simfe {

/* A textured planar rectangle in the world: texel (s, t) of its texture sits
 * at O + s U + t V (metres; U and V orthogonal, one texel long each). */
struct Surface {
    double O[3];
    double U[3];
    double V[3];
    int tex_w;       /* texels                                             */
    int tex_h;
    int atlas_x;     /* where the texture sits in the scene's atlas        */
    int atlas_y;
    bool on_plane;   /* the dominant plane (surface 0)                     */
};

/* Plane texture: grey, w x h texels, corners at several scales (rectangles,
 * rotated blocks and checker patches over a smooth background), the same
 * for the same seed. */
cv::Mat make_plane_texture(uint64_t seed, int w, int h);

/* Texture of an off-plane object, size x size texels; a different look from
 * the plane's so that its features are told apart. */
cv::Mat make_object_texture(uint64_t seed, int size);

/* A photograph as the plane's texture: the image file read in grey, scaled
 * to cover w x h texels with its aspect kept (bilinear) and cropped to its
 * centre.  Returns "" or a reason (unreadable file, empty image). */
std::string load_plane_texture(const std::string &path, int w, int h,
                               cv::Mat &out);

/* The scene: surface 0 is the plane, the others are off-plane quads.  All
 * textures live in one atlas so that one cv::remap renders a frame. */
struct Scene {
    sim_camera_t cam;          /* TRUE camera                             */
    std::vector<Surface> surf;
    cv::Mat atlas;             /* CV_8U                                   */

    /* Build from the plane: texture 2048 x 2048 texels of 12 cm centred
     * where the target camera's optical axis meets the plane, plus up to
     * n_objects quads (2.5..5 m wide) at depths [zmin, zmax) that the
     * target camera sees in front of the plane.  texture: an image file
     * for the plane (load_plane_texture), or empty for the procedural
     * one.  Returns "" or a reason. */
    std::string build(const sim_camera_t &cam, const sim_plane_t &pl,
                      uint64_t seed, int n_objects, double zmin_m,
                      double zmax_m, const std::string &texture = "");

    /* Cast the ray through centred pixel (x, y) of the camera at `pose`:
     * the index of the nearest surface hit (-1 for none) and the hit point
     * X (world, metres). */
    int cast(const sim_pose_t &pose, double x_px, double y_px,
             double X[3]) const;

    /* Render the 640x480 image at `pose` into img (CV_8U).  mapx, mapy and
     * depth are work buffers kept by the caller between frames. */
    void render(const sim_pose_t &pose, cv::Mat &img, cv::Mat &mapx,
                cv::Mat &mapy, cv::Mat &depth) const;
};

} // namespace simfe

#endif /* SIM_FRONTEND_INTERNAL_HPP */
