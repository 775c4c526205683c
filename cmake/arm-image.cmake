# servo_board_linker_script(OUT TEMPLATE): the board's linker script, made
# from hal/ports/stm32_common/linker/TEMPLATE.ld.in and the board's board.h by the C
# preprocessor (the board is the folder whose CMakeLists.txt calls this).
function(servo_board_linker_script out template)
  get_filename_component(board ${CMAKE_CURRENT_SOURCE_DIR} NAME)
  set(in ${PROJECT_SOURCE_DIR}/hal/ports/stm32_common/linker/${template}.ld.in)
  set(ld ${CMAKE_CURRENT_BINARY_DIR}/${template}.ld)
  add_custom_command(
    OUTPUT ${ld}
    COMMAND ${CMAKE_C_COMPILER} -E -P -x c -I${PROJECT_SOURCE_DIR}/firmware
            "-DSERVO_BOARD_H=\"boards/${board}/board.h\"" ${in} -o ${ld}
    DEPENDS ${in} ${CMAKE_CURRENT_SOURCE_DIR}/board.h ${PROJECT_SOURCE_DIR}/firmware/boards/board_derived.h
    COMMENT "Linker script ${template}.ld from ${CMAKE_CURRENT_SOURCE_DIR}/board.h"
    VERBATIM)
  if(NOT TARGET ${board}_${template}_ld)
    add_custom_target(${board}_${template}_ld DEPENDS ${ld})
  endif()
  set(${out} ${ld} PARENT_SCOPE)
endfunction()

# servo_board_facts(): the facts of the board whose folder calls it, through
# the one reader of them (bootloader/servo_image/board_facts.py:
# board.h's numbers, hex or decimal) as _BOARD_* variables, after holding
# them to the part its board.cmake names (hal/ports/parts.toml): its
# flash map within the part's flash and on its erase unit, its RAM within
# the part's, its CPU the part's. A board its part contradicts is not
# built, and the configure's error says which fact, a line each.
function(servo_board_facts)
  execute_process(
    COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/bootloader/servo_image/board_facts.py
            --check --facts ${CMAKE_CURRENT_SOURCE_DIR}
    RESULT_VARIABLE failed OUTPUT_VARIABLE facts ERROR_VARIABLE problems)
  if(failed)
    # A line a fact: a line that begins with a space is not rewrapped.
    string(STRIP "${problems}" problems)
    string(REPLACE "\n" "\n " problems " ${problems}")
    message(FATAL_ERROR "${problems}")
  endif()
  string(REPLACE "\n" ";" facts "${facts}")
  foreach(fact ${facts})
    if(fact MATCHES "^(BOARD_[A-Z0-9_]+)=([0-9]+)$")
      set(_${CMAKE_MATCH_1} ${CMAKE_MATCH_2} PARENT_SCOPE)
    endif()
  endforeach()
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS
               ${CMAKE_CURRENT_SOURCE_DIR}/board.h ${CMAKE_CURRENT_SOURCE_DIR}/board.cmake
               ${PROJECT_SOURCE_DIR}/hal/ports/parts.toml)
endfunction()

# servo_board_limits(): the limits an image of the board whose folder calls
# it is checked against, its own, unless its board.cmake sets them: the
# application's slot (board.h: BOARD_SLOT_PAGES x BOARD_FLASH_PAGE) less the
# update image's 256-byte header (bootloader/include/bootloader/app_image.h), and the
# part's RAM (BOARD_RAM_SIZE).
macro(servo_board_limits)
  servo_board_facts()
  if(NOT DEFINED SERVO_BOARD_FLASH_LIMIT)
    math(EXPR SERVO_BOARD_FLASH_LIMIT "${_BOARD_SLOT_PAGES} * ${_BOARD_FLASH_PAGE} - 256")
  endif()
  if(NOT DEFINED SERVO_BOARD_RAM_LIMIT)
    set(SERVO_BOARD_RAM_LIMIT ${_BOARD_RAM_SIZE})
  endif()
endmacro()

# servo_arm_image(NAME SOURCES src... [LIBS lib...]): the image of the board
# whose folder calls it (board.cmake: its startup code and port library;
# board.h: its flash map, read by the linker script made from it), a .bin
# beside it, a map, and the budget / soft-float and stack checks after every
# link.
function(servo_arm_image name)
  cmake_parse_arguments(I "" "" "SOURCES;LIBS" ${ARGN})
  if(NOT SERVO_BOARD_CPU STREQUAL SERVO_CPU)
    message(FATAL_ERROR "${name}: the board is a ${SERVO_BOARD_CPU}; this build is for ${SERVO_CPU} "
                        "(one build makes one CPU's boards: a cortex-m0 board in the arm-m0 preset, or -DSERVO_CPU=${SERVO_BOARD_CPU})")
  endif()
  servo_board_linker_script(I_LINKER app)
  get_filename_component(board ${CMAKE_CURRENT_SOURCE_DIR} NAME)
  servo_board_limits()
  add_executable(${name}.elf ${I_SOURCES} ${SERVO_BOARD_SOURCES} ${SERVO_BOARD_STARTUP})
  target_link_libraries(${name}.elf PRIVATE ${I_LIBS} ${SERVO_BOARD_PORT} servo_app)
  if(SERVO_SIZE_FIRST)
    target_sources(${name}.elf PRIVATE $<TARGET_OBJECTS:servo_small_runtime>
                   $<TARGET_OBJECTS:servo_small_div>)
  elseif(SERVO_CPU STREQUAL "cortex-m0plus")
    # The small run-time's mem* too: its memcpy reads an aligned source a
    # word a load (ReadBatchData's 32 bytes), the C library's a byte a step.
    target_sources(${name}.elf PRIVATE $<TARGET_OBJECTS:servo_small_memcpy>)
  endif()
  target_include_directories(${name}.elf PRIVATE ${PROJECT_SOURCE_DIR}/firmware ${PROJECT_SOURCE_DIR}/bootloader/include)
  add_dependencies(${name}.elf ${board}_app_ld)
  servo_firmware_target(${name}.elf)
  target_link_options(${name}.elf PRIVATE -L${PROJECT_SOURCE_DIR}/hal/ports/stm32_common/linker -T${I_LINKER}
                      -Wl,-Map=${CMAKE_CURRENT_BINARY_DIR}/${name}.map)
  set_target_properties(${name}.elf PROPERTIES
    LINK_DEPENDS "${I_LINKER};${PROJECT_SOURCE_DIR}/hal/ports/stm32_common/linker/sections_stm32.ld;${PROJECT_SOURCE_DIR}/cmake/check-image.sh")
  # The link-time partitions' call graphs (stack-report.py) are the last
  # link's alone.
  add_custom_command(TARGET ${name}.elf PRE_LINK
    COMMAND sh -c "rm -f ${CMAKE_CURRENT_BINARY_DIR}/${name}.elf.ltrans*" VERBATIM)
  add_custom_command(TARGET ${name}.elf POST_BUILD
    COMMAND ${CMAKE_OBJCOPY} -O binary $<TARGET_FILE:${name}.elf> ${CMAKE_CURRENT_BINARY_DIR}/${name}.bin
    COMMAND sh ${PROJECT_SOURCE_DIR}/cmake/check-image.sh $<TARGET_FILE:${name}.elf>
            ${SERVO_BOARD_FLASH_LIMIT} ${SERVO_BOARD_RAM_LIMIT}
    COMMAND Python3::Interpreter ${PROJECT_SOURCE_DIR}/cmake/stack-report.py
            $<TARGET_FILE:${name}.elf> ${CMAKE_BINARY_DIR}
    # The update image (header, then the application): what the bootloader
    # starts, servoctl update writes, and the slot holds.
    COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/bootloader/servo_image/__init__.py
            ${CMAKE_CURRENT_BINARY_DIR}/${name}.bin
            --version ${SERVO_FIRMWARE_VERSION} --board ${board}
            -o ${CMAKE_CURRENT_BINARY_DIR}/${name}.img
    VERBATIM)
endfunction()

# servo_arm_bootloader(NAME SOURCES src...): the bootloader of the board
# whose board.cmake was included last, at the start of flash, with its own
# budget (4 KB, and the part's RAM) checked after every link.
function(servo_arm_bootloader name)
  cmake_parse_arguments(I "" "" "SOURCES" ${ARGN})
  # Built for size (-Oz, link-time optimised) into the image itself, so
  # these objects come before the libraries' -Os ones: the bootloader core,
  # the framer byte by byte and deaf to SyncCommand (FRAME_RX_SMALL,
  # FRAME_RX_NO_SYNC), small mem* functions
  # (hal/runtime/small_mem.c), and the board's port with the drivers
  # it shares (unused ones drop out at the link).
  set(boot ${PROJECT_SOURCE_DIR}/bootloader)
  set(small ${PROJECT_SOURCE_DIR}/protocol/wire/frame_rx.c ${PROJECT_SOURCE_DIR}/protocol/wire/frame_rx_queue.c
      ${PROJECT_SOURCE_DIR}/hal/runtime/small_mem.c ${boot}/bootloader.c
      ${boot}/boot_packets.c ${boot}/boot_flow.c ${boot}/app_image.c ${boot}/slot_write.c
      ${PROJECT_SOURCE_DIR}/services/storage/config_peek.c ${PROJECT_SOURCE_DIR}/hal/runtime/crc32.c)
  # The port libraries whose sources it compiles (a family's cmake may name
  # its own: the G0's port compiles the shared drivers itself).
  if(NOT DEFINED SERVO_BOARD_PORT_LIBS)
    set(SERVO_BOARD_PORT_LIBS ${SERVO_BOARD_PORT} servo_stm32_common)
  endif()
  foreach(lib ${SERVO_BOARD_PORT_LIBS})
    get_target_property(dir ${lib} SOURCE_DIR)
    get_target_property(sources ${lib} SOURCES)
    list(TRANSFORM sources PREPEND ${dir}/ REGEX "^[^/]") # relative ones
    list(APPEND small ${sources})
  endforeach()
  add_executable(${name}.elf ${I_SOURCES} ${SERVO_BOARD_SOURCES} ${SERVO_BOARD_STARTUP} ${small})
  if(TARGET servo_small_div) # a core without a divide instruction (hal/runtime)
    target_sources(${name}.elf PRIVATE $<TARGET_OBJECTS:servo_small_div>)
  endif()
  target_compile_definitions(${name}.elf PRIVATE FRAME_RX_SMALL FRAME_RX_NO_SYNC STARTUP_BOOTLOADER CRC32_BITWISE)
  target_compile_options(${name}.elf PRIVATE -Oz -flto -fno-tree-loop-distribute-patterns)
  target_link_options(${name}.elf PRIVATE -Oz -flto)
  target_link_libraries(${name}.elf PRIVATE ${SERVO_BOARD_PORT} servo_bootloader_core)
  target_include_directories(${name}.elf PRIVATE ${PROJECT_SOURCE_DIR}/firmware)
  servo_firmware_target(${name}.elf)
  servo_board_limits()
  # The part's VTOR (parts.toml): the jump to the application sets it (boot_jump.c).
  target_compile_definitions(${name}.elf PRIVATE SERVO_PART_VTOR=${_BOARD_PART_VTOR})
  servo_board_linker_script(boot_ld boot)
  get_filename_component(board ${CMAKE_CURRENT_SOURCE_DIR} NAME)
  add_dependencies(${name}.elf ${board}_boot_ld)
  target_link_options(${name}.elf PRIVATE -L${PROJECT_SOURCE_DIR}/hal/ports/stm32_common/linker
                      -T${boot_ld} -Wl,-Map=${CMAKE_CURRENT_BINARY_DIR}/${name}.map)
  set_target_properties(${name}.elf PROPERTIES
    LINK_DEPENDS "${boot_ld};${PROJECT_SOURCE_DIR}/hal/ports/stm32_common/linker/sections_stm32.ld")
  add_custom_command(TARGET ${name}.elf POST_BUILD
    COMMAND ${CMAKE_OBJCOPY} -O binary $<TARGET_FILE:${name}.elf> ${CMAKE_CURRENT_BINARY_DIR}/${name}.bin
    COMMAND sh ${PROJECT_SOURCE_DIR}/cmake/check-image.sh $<TARGET_FILE:${name}.elf> ${_BOARD_BOOT_SIZE}
            ${SERVO_BOARD_RAM_LIMIT}
    VERBATIM)
endfunction()

# servo_board_images(): the images of the board whose folder calls it: its
# bootloader (boot_main.c) and its application (main.c). A main loop that
# hangs is the virtual boards' injection (tools/vboard/inject.py), on the
# shipped image.
# Its code is its folder's, or the folder its board.cmake names
# (SERVO_BOARD_CODE: a family's shared code, which includes the board's
# board.h by bare name from the board's folder, on the include path).
function(servo_board_images)
  get_filename_component(board ${CMAKE_CURRENT_SOURCE_DIR} NAME)
  if(NOT DEFINED SERVO_BOARD_CODE)
    set(SERVO_BOARD_CODE ${CMAKE_CURRENT_SOURCE_DIR})
  endif()
  servo_arm_bootloader(servo_${board}_boot SOURCES ${SERVO_BOARD_CODE}/boot_main.c)
  servo_arm_image(servo_${board} SOURCES ${SERVO_BOARD_CODE}/main.c)
  foreach(image servo_${board}_boot servo_${board})
    target_include_directories(${image}.elf BEFORE PRIVATE ${CMAKE_CURRENT_SOURCE_DIR})
  endforeach()
endfunction()
