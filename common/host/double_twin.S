// A reference's double build, carried as data by its float binary (double_twin.h). The
// Makefile assembles this file once per twin, with TWIN_PATH the double binary to carry. The
// section keeps its own name in the linked binary (a .rodata.* one would merge into .rodata),
// so the grader can find the twin and stage it as a file (labkit/double_twin.py).
    .section rt_double_twin, "a"
    .balign 16
    .globl rt_double_twin_begin
rt_double_twin_begin:
    .incbin TWIN_PATH
    .globl rt_double_twin_end
rt_double_twin_end:
    .section .note.GNU-stack, "", @progbits
