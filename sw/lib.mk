# sw/lib.mk - the rules every C library of sw/ (hsr, yproc) builds itself with: one object
# per source (so `make -j` compiles in parallel), plain in $(B)/obj and with ASan/UBSan in
# $(B)/san (shared by the sanitized tests and the fuzz targets), and the two archives.
# Set before including: LIB (archive name), SRC, HDR, WARN, CFLAGS, SAN, B.
OBJ := $(patsubst src/%.c,$(B)/obj/%.o,$(SRC))
SOBJ := $(patsubst src/%.c,$(B)/san/%.o,$(SRC))

$(B)/obj/%.o: src/%.c $(HDR) | $(B)/obj
	$(CC) $(WARN) $(CFLAGS) -c -o $@ $<

$(B)/san/%.o: src/%.c $(HDR) | $(B)/san
	$(CC) $(WARN) -O1 -g $(SAN) -c -o $@ $<

$(B)/$(LIB).a: $(OBJ)
	rm -f $@
	ar rcs $@ $(OBJ)

$(B)/$(LIB)_san.a: $(SOBJ)
	rm -f $@
	ar rcs $@ $(SOBJ)

$(B) $(B)/obj $(B)/san:
	mkdir -p $@
