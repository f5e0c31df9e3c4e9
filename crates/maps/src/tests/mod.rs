mod blending;
mod png_files;
mod sampling;
