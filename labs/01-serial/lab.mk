# Lab 01: serial. ./lab01 (skeleton) and ./lab01-ref (solution).
$(eval $(call cpu_lab,lab01,01-serial,))
VARIANT_DRIVER_01-serial := $(COMMON_OBJ)
