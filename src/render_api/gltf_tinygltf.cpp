// The implementations of tinygltf and of stb_image and stb_image_write (which tiny_gltf.h
// includes): the one translation unit of the project that defines them, so that each is
// compiled once. The glTF loader (gltf_*.cpp) and the image files (image_io.cpp) include only
// their declarations.
#include <fstream> // tiny_gltf.h 2.7.0 uses std::ofstream without including it

#define TINYGLTF_IMPLEMENTATION
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <tiny_gltf.h>
