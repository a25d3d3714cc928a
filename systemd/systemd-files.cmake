# canmotion's systemd files and default configuration, filled in for an
# installation prefix. Included twice from the same code:
#  - at configure time by systemd/CMakeLists.txt, for the build's
#    CMAKE_INSTALL_PREFIX (the copies in <build>/systemd/ are what the tests
#    check);
#  - at install time by the generated install-systemd.cmake, for the prefix in
#    force then (`cmake --install --prefix ...`, or /usr when CPack builds the
#    Debian package), so that the units name the paths they are installed with.
#
# Expects: CMAKE_INSTALL_PREFIX, CMAKE_INSTALL_{BINDIR,SYSCONFDIR,LIBDIR}
# (relative or absolute, as GNUInstallDirs has them), CANMOTION_SYSTEMD_SRC
# (the source folder systemd/), and for install: the CANMOTION_SYSTEMD_PC_*
# variables written by systemd/CMakeLists.txt.

# Templates: @CMAKE_INSTALL_FULL_BINDIR@ and @CMAKE_INSTALL_FULL_SYSCONFDIR@ are
# replaced. Plain files are copied as they are.
set(CANMOTION_SYSTEMD_UNIT_TEMPLATES canmotiond.service cia402-emu@.service)
set(CANMOTION_SYSTEMD_UNITS canmotion-vcan@.service)
set(CANMOTION_SYSTEMD_NETWORK 80-vcan0.netdev 80-vcan0.network)
set(CANMOTION_SYSTEMD_UDEV 60-canmotion-cpu-dma-latency.rules)

# canmotion_systemd_configure(OUT_DIR): the filled-in units and the plain files
# (units, networkd files, sysusers.d file, emulator example) in OUT_DIR, for
# CMAKE_INSTALL_PREFIX as it is now.
function(canmotion_systemd_configure out)
  include(GNUInstallDirs)  # CMAKE_INSTALL_FULL_* for the current prefix (/usr -> /etc)
  file(MAKE_DIRECTORY "${out}")
  foreach(t IN LISTS CANMOTION_SYSTEMD_UNIT_TEMPLATES)
    configure_file("${CANMOTION_SYSTEMD_SRC}/${t}.in" "${out}/${t}" @ONLY)
  endforeach()
  foreach(f IN LISTS CANMOTION_SYSTEMD_UNITS CANMOTION_SYSTEMD_NETWORK CANMOTION_SYSTEMD_UDEV ITEMS canmotion.sysusers.conf cia402-emu-example.conf)
    configure_file("${CANMOTION_SYSTEMD_SRC}/${f}" "${out}/${f}" COPYONLY)
  endforeach()
endfunction()

# canmotion_systemd_dir(OUT KIND): where systemd looks for KIND (UNIT, SYSUSERS,
# NETWORK, UDEV) files of a package installed in CMAKE_INSTALL_PREFIX. A prefix equal
# to systemd's own (pkg-config systemd: prefix=/usr on Debian) gets systemd's
# directories as they are (/lib/systemd/system on Debian 12); another prefix
# the same path below it (/usr/local/lib/systemd/system, also searched by systemd).
function(canmotion_systemd_dir out kind)
  if(CANMOTION_SYSTEMD_${kind}DIR)  # set by the user: -DCANMOTION_SYSTEMD_UNITDIR=... (relative: below the prefix)
    set(dir "${CANMOTION_SYSTEMD_${kind}DIR}")
    if(NOT IS_ABSOLUTE "${dir}")
      set(dir "${CMAKE_INSTALL_PREFIX}/${dir}")
    endif()
    set(${out} "${dir}" PARENT_SCOPE)
  elseif(CMAKE_INSTALL_PREFIX STREQUAL CANMOTION_SYSTEMD_PC_PREFIX)
    set(${out} "${CANMOTION_SYSTEMD_PC_${kind}}" PARENT_SCOPE)
  else()
    set(${out} "${CMAKE_INSTALL_PREFIX}/${CANMOTION_SYSTEMD_PC_${kind}_REL}" PARENT_SCOPE)
  endif()
endfunction()

# canmotion_systemd_install(STAGING_DIR): configure for the current prefix into
# STAGING_DIR and install (file(INSTALL) honours DESTDIR). The default
# configuration is installed only where none exists yet, so that
# `cmake --install` never overwrites an edited one (dpkg handles it as a conffile).
function(canmotion_systemd_install staging)
  file(REMOVE_RECURSE "${staging}")
  canmotion_systemd_configure("${staging}")
  include(GNUInstallDirs)
  canmotion_systemd_dir(unitdir UNIT)
  canmotion_systemd_dir(sysusersdir SYSUSERS)
  canmotion_systemd_dir(networkdir NETWORK)
  canmotion_systemd_dir(udevdir UDEV)
  set(units ${CANMOTION_SYSTEMD_UNIT_TEMPLATES} ${CANMOTION_SYSTEMD_UNITS})
  list(TRANSFORM units PREPEND "${staging}/")
  set(network ${CANMOTION_SYSTEMD_NETWORK})
  list(TRANSFORM network PREPEND "${staging}/")
  file(INSTALL ${units} DESTINATION "${unitdir}" FILE_PERMISSIONS OWNER_READ OWNER_WRITE GROUP_READ WORLD_READ)
  file(INSTALL ${network} DESTINATION "${networkdir}" FILE_PERMISSIONS OWNER_READ OWNER_WRITE GROUP_READ WORLD_READ)
  set(udev ${CANMOTION_SYSTEMD_UDEV})
  list(TRANSFORM udev PREPEND "${staging}/")
  file(INSTALL ${udev} DESTINATION "${udevdir}" FILE_PERMISSIONS OWNER_READ OWNER_WRITE GROUP_READ WORLD_READ)
  file(INSTALL "${staging}/canmotion.sysusers.conf" DESTINATION "${sysusersdir}" RENAME canmotion.conf
       FILE_PERMISSIONS OWNER_READ OWNER_WRITE GROUP_READ WORLD_READ)
  set(confdir "${CMAKE_INSTALL_FULL_SYSCONFDIR}/canmotion")
  if(EXISTS "$ENV{DESTDIR}${confdir}/canmotiond.yaml")
    message(STATUS "Keeping: $ENV{DESTDIR}${confdir}/canmotiond.yaml (exists; the default is in the examples)")
  else()
    file(INSTALL "${CANMOTION_DEFAULT_CONFIG}" DESTINATION "${confdir}"
         FILE_PERMISSIONS OWNER_READ OWNER_WRITE GROUP_READ WORLD_READ)
  endif()
  file(REMOVE_RECURSE "${staging}")
endfunction()
