// Entry point of every lab binary: the shared command line and render driver.
#include <lab.h>

int main(int argc, char** argv) { return lab_main(argc, argv); }
