# ibmdem — build, test, validate, benchmark.
#   make            build build/ibmdem and the test/bench programs
#   make test       install missing Debian packages, build, run the test suite (1 and 2 ranks)
#   make demo       install, build, run the built-in demo case and plot it
#   make validate   full-size validation cases (long)
#   make restitution  restitution sweeps (wall and binary; about 15 min on 2 cores);
#                   RESTITUTION_SET='section.key=value ...' overrides keys in every run,
#                   RESTITUTION_OUT=dir the output directory (default build/restitution)
#   make viscous_stability  the stability map of the coupled step at large viscous numbers
#                   (build/viscous_stability/map.md; ~25 min on 2 cores)
#   make avalanche  the immersed avalanche's regime map in the quick box (build/avalanche/map.md, map_map.png);
#                   make avalanche_production: Table 4.3 in the production box
#   make bounce     the bouncing sphere against experiments, lubrication cut-off, oblique bounces (FULL=1: finer)
#   make fuzz       the long fuzz series of tests/fuzz.py (40 check and 8 run mutants of every case file;
#                   FUZZ_SEED=N other mutants, FUZZ_ARGS='--checks 200' more); make test runs a quick subset
#   make bench      benchmarks, results appended to docs/performance.md
#   make deps       install missing Debian packages (apt-get)
#   SANITIZE=1      build with AddressSanitizer + UBSan into build-san/

CC      := mpicc
STD     := -std=c11 -D_POSIX_C_SOURCE=200809L -D_DEFAULT_SOURCE
# -Wno-missing-field-initializers: the key tables (cfg_key_t) leave the trailing `need` of the
# keys that have a default to its zero value, as C guarantees
WARN    := -Wall -Wextra -Wno-unused-parameter -Wno-missing-field-initializers
HDF5_CFLAGS := $(shell pkg-config --cflags hdf5-openmpi 2>/dev/null)
HDF5_LIBS   := $(shell pkg-config --libs hdf5-openmpi 2>/dev/null)
ifeq ($(SANITIZE),1)
BUILD   ?= build-san
OPT     := -O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined
else
BUILD   ?= build
OPT     := -O3 -march=native -g
endif
CFLAGS  := $(STD) $(OPT) $(WARN) -Iinclude $(HDF5_CFLAGS) $(EXTRA_CFLAGS)
LDLIBS  := $(HDF5_LIBS) -lfftw3_mpi -lfftw3 -lgsl -lgslcblas -lqhull_r -lcholmod -lsuitesparseconfig \
           -lgmp -lmpfr -lstdc++ -lm -fopenmp
# C++ (CGAL's regular triangulation, src/porenet/regular_cgal.cpp): interval
# arithmetic of the exact predicates needs -frounding-math
CXX     := g++
CXXFLAGS := -std=c++17 $(OPT) -Wall -Wextra -frounding-math -Iinclude $(EXTRA_CFLAGS)
TESTLIBS := -lcmocka

SRC     := $(filter-out src/main.c,$(shell find src -name '*.c' | sort))
CXXSRC  := $(shell find src -name '*.cpp' | sort)
OBJ     := $(patsubst src/%.c,$(BUILD)/obj/%.o,$(SRC)) $(patsubst src/%.cpp,$(BUILD)/obj/%.o,$(CXXSRC))
DEP     := $(OBJ:.o=.d)
LIB     := $(BUILD)/libibmdem.a
BIN     := $(BUILD)/ibmdem
TESTS   := $(patsubst tests/%.c,$(BUILD)/tests/%,$(wildcard tests/test_*.c))
BENCHES := $(patsubst bench/%.c,$(BUILD)/bench/%,$(wildcard bench/bench_*.c))

.PHONY: all test demo validate bench deps clean restitution viscous_stability bounce fuzz avalanche avalanche_production crosscheck collapse
all: $(BIN) $(TESTS) $(BENCHES)

$(BUILD)/obj/%.o: src/%.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -MMD -MP -c $< -o $@

$(BUILD)/obj/%.o: src/%.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS) -MMD -MP -c $< -o $@

# The DEM kernels take square roots of non-negative numbers only: without errno
# handling the contact loop of src/dem/dem_kernel.inc vectorises (SIMD).  The
# DEM uses OpenMP threads ([dem] threads; one thread by default).
$(BUILD)/obj/dem/%.o: CFLAGS += -fno-math-errno -fopenmp
# The same for the solid fraction of the immersed boundary (src/ibm/alpha.c).
$(BUILD)/obj/ibm/%.o: CFLAGS += -fno-math-errno
# ... and for bench_ibm's floor, which evaluates the same profile on flat arrays.
$(BUILD)/bench/bench_ibm: CFLAGS += -fno-math-errno

$(LIB): $(OBJ)
	@rm -f $@
	ar rcs $@ $^

$(BIN): src/main.c $(LIB)
	$(CC) $(CFLAGS) $< $(LIB) $(LDLIBS) -o $@

$(BUILD)/tests/%: tests/%.c $(wildcard tests/*.h) $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -Itests $< $(LIB) $(LDLIBS) $(TESTLIBS) -o $@

$(BUILD)/bench/%: bench/%.c $(wildcard bench/*.h) $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $< $(LIB) $(LDLIBS) -o $@

-include $(DEP)

deps:
	@bash scripts/deps.sh

test: deps
	@$(MAKE) --no-print-directory all
	@BUILD=$(BUILD) bash tests/run.sh

demo: deps
	@$(MAKE) --no-print-directory $(BIN)
	@BUILD=$(BUILD) bash scripts/demo.sh

validate: deps
	@$(MAKE) --no-print-directory all
	@BUILD=$(BUILD) bash scripts/validate.sh

bench: deps
	@$(MAKE) --no-print-directory all
	@BUILD=$(BUILD) bash bench/run.sh

# ibmdem against OpenFOAM (installed from Debian if missing) on the simple cubic array:
# build/crosscheck/{table.md,speed_error.png} (bench/crosscheck/run.sh: CASES, METHODS)
crosscheck: deps
	@$(MAKE) --no-print-directory $(BIN)
	@BUILD=$(BUILD) bash bench/crosscheck/run.sh

# restitution curves of the bouncing sphere and the binary collision: the sweep in
# parallel on the available cores, build/restitution/{restitution,binary}.{csv,png}, target checks
RESTITUTION_OUT ?= $(BUILD)/restitution
restitution: deps
	@$(MAKE) --no-print-directory all
	@BUILD=$(BUILD) bash scripts/restitution.sh $(RESTITUTION_OUT) full $(RESTITUTION_SET)

# the stability map of the coupled step at large viscous numbers (docs/theory.md §4.6, §9.1):
# build/viscous_stability/map.md
viscous_stability: deps
	@$(MAKE) --no-print-directory all
	@BUILD=$(BUILD) bash scripts/viscous_stability.sh $(BUILD)/viscous_stability
# the immersed avalanche (Izard ch. 4): the regime map and Table 4.3 in the quick box, build/avalanche/map*;
# avalanche_production: Table 4.3 in the production box (several hours on 2 cores)
avalanche: deps
	@$(MAKE) --no-print-directory all
	@BUILD=$(BUILD) bash scripts/avalanche.sh $(BUILD)/avalanche map
avalanche_production: deps
	@$(MAKE) --no-print-directory all
	@BUILD=$(BUILD) bash scripts/avalanche.sh $(BUILD)/avalanche production
# the immersed column collapse, Table 5.1 cases A, D, E, F at D/dx = 10 on NP = 2 ranks and A, F with the
# pore network: build/collapse/{collapse.md,collapse.png} with issue 20's targets (scripts/collapse.sh)
collapse: deps
	@$(MAKE) --no-print-directory all
	@BUILD=$(BUILD) bash scripts/collapse.sh $(BUILD)/collapse all
# the bouncing sphere against the experiments of Gondret et al. (2002), the lubrication cut-off and the
# oblique bounces (part of make validate); FULL=1 adds D/dx = 40 (and 30 at St 152): about 3 hours
bounce: deps
	@$(MAKE) --no-print-directory all
	@BUILD=$(BUILD) OUT=$(BUILD)/bounce FULL=$(FULL) bash scripts/validate_bounce.sh

# mutated case files through check and a few steps of run, clean outcomes only (part of make validate)
FUZZ_SEED ?= 17
fuzz: deps
	@$(MAKE) --no-print-directory $(BIN)
	@/usr/bin/python3 tests/fuzz.py --bin $(BIN) --seed $(FUZZ_SEED) --checks 40 --runs 8 $(FUZZ_ARGS)

clean:
	rm -rf build build-san
