/* libvasco_gpu.so is made of the static libraries' objects, linked whole;
 * CMake wants at least one source file of its own for a library target. */
typedef int vasco_gpu_shared_library_has_no_code_of_its_own;
