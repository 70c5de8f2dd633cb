# What `cmake --install build --prefix P` puts where (the layout: CMakeLists.txt, "An installed
# tree"), the CMake package other projects find with find_package(vgpu_rt CONFIG), the man page,
# and the Debian packages CPack builds from the same rules (`cpack -G DEB` in the build folder).
include(CMakePackageConfigHelpers)

# The libraries, static as the build makes them, under the names other projects use:
# vgpu_rt::vgpu (the virtual GPU; it carries the target flags a kernel must share, vgpu_abi),
# vgpu_rt::kernels (the paper's kernels), vgpu_rt::host (the host library: scenes, structures,
# the tracers, the report and the render call the command line makes), and the parts of host.
set(VGPU_EXPORTED vgpu_abi vgpu kernels host_common host_scene host_image host_accel host_model
                  host_trace host_report host_cli)
if(TARGET gl)
  list(APPEND VGPU_EXPORTED gl)
endif()
add_library(host INTERFACE)
target_link_libraries(host INTERFACE host_cli)
# A program built against an installed tree finds its scenes and image module through the
# prefix (host/common/install_paths.h); the build tree's own programs need no such definition.
target_compile_definitions(
  host_common PUBLIC $<INSTALL_INTERFACE:VGPU_RT_INSTALL_PREFIX="$<INSTALL_PREFIX>">)
install(TARGETS ${VGPU_EXPORTED} host EXPORT vgpu_rtTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT dev
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/vgpu_rt)
install(EXPORT vgpu_rtTargets NAMESPACE vgpu_rt:: DESTINATION ${VGPU_CMAKE_INSTALL_DIR}
        COMPONENT dev)
# The public headers, under one folder, by the paths the sources include them with
# (#include "vgpu/gpu.h").
foreach(dir vgpu kernels gl host)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${dir} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/vgpu_rt
          COMPONENT dev FILES_MATCHING PATTERN "*.h" PATTERN "node_modules" EXCLUDE)
endforeach()
configure_package_config_file(
  ${PROJECT_SOURCE_DIR}/cmake/vgpu_rtConfig.cmake.in
  ${PROJECT_BINARY_DIR}/cmake/vgpu_rtConfig.cmake INSTALL_DESTINATION ${VGPU_CMAKE_INSTALL_DIR}
  PATH_VARS VGPU_DATA_INSTALL_DIR)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/cmake/vgpu_rtConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/cmake/vgpu_rtConfig.cmake
              ${PROJECT_BINARY_DIR}/cmake/vgpu_rtConfigVersion.cmake
        DESTINATION ${VGPU_CMAKE_INSTALL_DIR} COMPONENT dev)

# The command line, the image module and the scenes.
install(TARGETS vgpu-rt RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
install(TARGETS vgpu-image LIBRARY DESTINATION ${VGPU_MODULE_INSTALL_DIR} COMPONENT runtime)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/scenes/ DESTINATION ${VGPU_DATA_INSTALL_DIR}/scenes
        COMPONENT runtime)

# The man page, made from --help by Debian's help2man (scripts/man.sh adds each subcommand's
# options). Left out, with a note, where help2man is missing or the binary cannot run here.
find_program(VGPU_HELP2MAN help2man)
if(VGPU_HELP2MAN AND NOT VGPU_SANITIZE)
  add_custom_command(
    OUTPUT ${PROJECT_BINARY_DIR}/man/vgpu-rt.1.gz
    COMMAND ${PROJECT_SOURCE_DIR}/scripts/man.sh $<TARGET_FILE:vgpu-rt> ${VGPU_HELP2MAN}
            ${PROJECT_BINARY_DIR}/man/vgpu-rt.1
    DEPENDS vgpu-rt ${PROJECT_SOURCE_DIR}/scripts/man.sh
    COMMENT "Making the man page vgpu-rt.1 from --help (help2man)")
  add_custom_target(man ALL DEPENDS ${PROJECT_BINARY_DIR}/man/vgpu-rt.1.gz)
  install(FILES ${PROJECT_BINARY_DIR}/man/vgpu-rt.1.gz DESTINATION ${CMAKE_INSTALL_MANDIR}/man1
          COMPONENT runtime)
else()
  message(STATUS "vgpu-rt: help2man not found: no man page (scripts/setup.sh installs it)")
endif()

# Debian packages: vgpu-rt (the command line, the scenes, the Python module, the man page) and
# vgpu-rt-dev (headers, static libraries, the CMake package). Their library dependencies are
# read from the binaries (dpkg-shlibdeps); the rest is declared here.
set(CPACK_PACKAGE_NAME vgpu-rt)
set(CPACK_PACKAGE_VENDOR "vgpu-rt")
set(CPACK_PACKAGE_CONTACT "vgpu-rt developers <vgpu-rt@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "virtual 2004 GPU and the stream ray tracer of Fal, Vasconcelos & Delrieux")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_DIRECTORY ${PROJECT_BINARY_DIR}/packages)
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_GROUPING IGNORE)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION graphics)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_HOMEPAGE "https://example.invalid/vgpu-rt")
set(CPACK_DEBIAN_RUNTIME_PACKAGE_NAME vgpu-rt)
set(CPACK_DEBIAN_DEV_PACKAGE_NAME vgpu-rt-dev)
if(VGPU_PYTHON)  # the extension is built for one Python version (python/CMakeLists.txt)
  math(EXPR next "${Python_VERSION_MINOR} + 1")
  set(CPACK_DEBIAN_RUNTIME_PACKAGE_DEPENDS
      "python3 (>= ${Python_VERSION_MAJOR}.${Python_VERSION_MINOR}), python3 (<< ${Python_VERSION_MAJOR}.${next}), python3-numpy")
endif()
set(CPACK_DEBIAN_DEV_PACKAGE_DEPENDS
    "vgpu-rt (= ${PROJECT_VERSION}), libglm-dev, nlohmann-json3-dev, libcli11-dev, zlib1g-dev, libegl-dev, libopengl-dev, libgl-dev, g++ (>= 4:12)")
# The first line is the summary; CPack indents the others.
set(CPACK_DEBIAN_RUNTIME_DESCRIPTION
    "virtual 2004 GPU and the stream ray tracer of Fal, Vasconcelos & Delrieux
vgpu-rt models a 2004 programmable fragment pipeline (textures, passes,
occlusion queries, the cards' limits and costs) and runs on it the multipass
stream ray tracer of Fal, Vasconcelos & Delrieux (after Purcell et al. 2002):
the vgpu-rt command line, the bundled scenes and the Python module vgpu_rt.")
set(CPACK_DEBIAN_DEV_DESCRIPTION
    "vgpu-rt's C++ library: headers, static libraries, CMake package
find_package(vgpu_rt CONFIG) gives the targets vgpu_rt::vgpu, vgpu_rt::kernels
and vgpu_rt::host, for kernels and programs of your own.")
set(CPACK_COMPONENTS_ALL runtime dev)
include(CPack)
