# native_posix: the image is a host executable. Nothing to flash; `ninja run` executes it.
set(SAFELINE_BOARD_ARCH posix)
