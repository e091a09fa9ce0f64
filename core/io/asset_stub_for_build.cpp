// placeholder so mm_io has a source while core/io is written; replaced by the io module
