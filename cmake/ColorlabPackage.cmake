# The Debian package (docs/packaging.md): `cpack --config build/CPackConfig.cmake` packages what the install rules
# install, under /usr, from the tree already built. Maintainer scripts in packaging/deb create the colorlab user,
# write the first configuration and reload udev; they never start the service.
set(COLORLAB_DEB_RELEASE 1 CACHE STRING "Debian revision of the package (the part after the upstream version)")
set(COLORLAB_DEB_VERSION "${PROJECT_VERSION}-${COLORLAB_DEB_RELEASE}")

# Debian's changelog and copyright, where lintian and `apt changelog` look; gzip -n keeps the build reproducible.
set(_deb_dir ${CMAKE_BINARY_DIR}/packaging/deb)
configure_file(${PROJECT_SOURCE_DIR}/packaging/deb/changelog.in ${_deb_dir}/changelog.Debian @ONLY)
execute_process(COMMAND gzip -9nf ${_deb_dir}/changelog.Debian RESULT_VARIABLE _gzip)
if(NOT _gzip EQUAL 0)
  message(FATAL_ERROR "gzip ${_deb_dir}/changelog.Debian failed (${_gzip})")
endif()
install(FILES ${_deb_dir}/changelog.Debian.gz ${PROJECT_SOURCE_DIR}/packaging/deb/copyright
        DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(FILES ${PROJECT_SOURCE_DIR}/packaging/deb/lintian-overrides
        DESTINATION ${CMAKE_INSTALL_DATADIR}/lintian/overrides RENAME colorlab)

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME colorlab)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_VENDOR "colorlab team")
set(CPACK_PACKAGE_CONTACT "colorlab team <team@colorlab.invalid>")
# DESTDIR staging, so the install rules see the real prefix (the systemd unit names /usr/sbin/colorlabd).
set(CPACK_SET_DESTDIR ON)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_INSTALL_PREFIX /usr)
# RelWithDebInfo binaries carry their debug info; the package does not.
set(CPACK_STRIP_FILES ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_RELEASE ${COLORLAB_DEB_RELEASE})
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
set(CPACK_DEBIAN_PACKAGE_DESCRIPTION "measurement daemon for a colour lab
colorlab drives a colour lab's instruments (spectrophotometer, luminance
meter, lamps and dimmer, tethered cameras), runs scripted capture campaigns
unattended, analyses what they capture, stores it in SQLite and serves it over
an HTTP API. This package holds the daemon colorlabd, the command-line client
colorlab, the simulated lab colorlab-sim, the Python client, the web console,
the shipped campaigns, the systemd unit and the udev rules; and for a lab of
several benches the shipping agent colorlab-ship (ended runs to PostgreSQL
and an S3 store) and the central read API colorlab-central, whose units are
installed but not enabled.")
# Shared libraries through dpkg-shlibdeps on the stripped binaries (libpq5 and libcurl for the fleet's programs);
# the rest is what the binaries and scripts use
# at run time: CIE tables (colord-data), the Python client's imports, the user's creation (adduser).
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_DEPENDS
    "adduser, colord-data, python3, python3-numpy, python3-pandas, python3-requests")
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "bash-completion, python3-matplotlib")
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "argyll")
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA
    ${PROJECT_SOURCE_DIR}/packaging/deb/postinst
    ${PROJECT_SOURCE_DIR}/packaging/deb/prerm
    ${PROJECT_SOURCE_DIR}/packaging/deb/postrm)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
include(CPack)
