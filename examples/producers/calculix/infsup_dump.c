
/* infsup-contact (examples/producers/calculix): appended to contactmortar.c by install.sh.
   When the environment variable INFSUP_CCX_DUMP names a directory, the first call of
   contactmortar writes the mortar coupling matrices that bdfill has just assembled, node by
   node (CalculiX's storage: column = node, irow = 1-based row node, jq = 1-based pointers of
   nk + 1 entries), as MatrixMarket files nk x nk in 1-based node numbers:
     Bd.mtx  (slave rows, master columns), Dd.mtx (slave rows, slave columns),
     Bpgd.mtx, Dpgd.mtx (the Petrov-Galerkin pair, PGMORTAR/PGLINMORTAR only),
   islavact.txt (slave node, its state: -3 no slave, -2 no LM, -1 no gap, 0 inactive, 1 stick,
   2 slip) and info.txt (nk, iflagdualquad). Nothing is changed in the computation; with
   INFSUP_CCX_DUMP_STOP also set, ccx exits right after the dump (the solves that follow are
   not needed for the coupling, and are most of a large run's time). */

static void infsup_write_mtx(const char *dir, const char *name, ITG nk,
                             const double *val, const ITG *irow, const ITG *jq){
  char path[1024];
  FILE *f;
  ITG node, jj;
  snprintf(path, sizeof(path), "%s/%s", dir, name);
  if((f = fopen(path, "w")) == NULL){
    printf(" *ERROR in infsup_ccx_dump: cannot open %s for writing\n", path);
    return;
  }
  fprintf(f, "%%%%MatrixMarket matrix coordinate real general\n");
  fprintf(f, "%" ITGFORMAT " %" ITGFORMAT " %" ITGFORMAT "\n", nk, nk, jq[nk] - 1);
  for(node = 0; node < nk; node++){
    for(jj = jq[node] - 1; jj < jq[node + 1] - 1; jj++){
      fprintf(f, "%" ITGFORMAT " %" ITGFORMAT " %.17g\n", irow[jj], node + 1, val[jj]);
    }
  }
  fclose(f);
}

static void infsup_ccx_dump(ITG *nk, ITG *ntie, ITG *nslavnode, ITG *islavnode,
                            ITG *islavact, ITG *iflagdualquad,
                            double *Bd, ITG *irowb, ITG *jqb,
                            double *Dd, ITG *irowd, ITG *jqd,
                            double *Bpgd, ITG *irowbpg, ITG *jqbpg,
                            double *Dpgd, ITG *irowdpg, ITG *jqdpg){
  static int done = 0;
  const char *dir = getenv("INFSUP_CCX_DUMP");
  char path[1024];
  FILE *f;
  ITG j;
  if(dir == NULL || dir[0] == '\0' || done) return;
  done = 1;
  infsup_write_mtx(dir, "Bd.mtx", *nk, Bd, irowb, jqb);
  infsup_write_mtx(dir, "Dd.mtx", *nk, Dd, irowd, jqd);
  if(*iflagdualquad > 2){
    infsup_write_mtx(dir, "Bpgd.mtx", *nk, Bpgd, irowbpg, jqbpg);
    infsup_write_mtx(dir, "Dpgd.mtx", *nk, Dpgd, irowdpg, jqdpg);
  }
  snprintf(path, sizeof(path), "%s/islavact.txt", dir);
  if((f = fopen(path, "w")) != NULL){
    for(j = 0; j < nslavnode[*ntie]; j++){
      fprintf(f, "%" ITGFORMAT " %" ITGFORMAT "\n", islavnode[j], islavact[j]);
    }
    fclose(f);
  }
  snprintf(path, sizeof(path), "%s/info.txt", dir);
  if((f = fopen(path, "w")) != NULL){
    fprintf(f, "nk %" ITGFORMAT "\niflagdualquad %" ITGFORMAT "\n", *nk, *iflagdualquad);
    fclose(f);
  }
  printf(" infsup-contact: mortar coupling written to %s\n", dir);
  if(getenv("INFSUP_CCX_DUMP_STOP") != NULL){
    printf(" infsup-contact: stopping after the dump (INFSUP_CCX_DUMP_STOP)\n");
    fflush(stdout);
    exit(0);
  }
}
