/*
 * Dense linear algebra for the native FMU (C99, libc and libm only): solve with
 * partial pivoting (and after a symmetric power-of-two scaling), the matrix
 * exponential, eigenvalues.  Matrices are row-major, n x n with leading dimension n
 * unless said otherwise.  Every routine checks that its input and its result are
 * finite and returns 0 on success, -1 otherwise; none can loop forever.
 */
#ifndef LCV_LINALG_H
#define LCV_LINALG_H

#include <stddef.h>

/* C = A B; A is r x k (lda), B is k x c (ldb), C is r x c (ldc) */
void lcv_matmul(const double *A, int lda, const double *B, int ldb, double *C, int ldc, int r, int k, int c);

/* A X = B in place (A destroyed, B overwritten by X; A n x n, B n x nrhs with leading dimension ldb) */
int lcv_solve(double *A, int n, double *B, int ldb, int nrhs);

/* M X = B with M scaled symmetrically by powers of two first (exact), as
   lcvreport.util.numerics.solve_scaled; M is not changed; work holds n*n + n doubles */
int lcv_solve_scaled(const double *M, int n, double *B, int ldb, int nrhs, double *work);

/* doubles of workspace lcv_expm needs for an n x n matrix */
size_t lcv_expm_work(int n);

/* E = exp(A): scaling and squaring with a Pade approximant, degree and squarings as in
   Al-Mohy and Higham (2009), Algorithm 5.1 -- the algorithm of scipy.linalg.expm and of
   lcvreport.util.numerics.expm */
int lcv_expm(const double *A, int n, double *E, double *work);

/* eigenvalues (wr + i wi) of a real n x n matrix a (destroyed): balancing, Hessenberg
   reduction, shifted QR (EISPACK balanc, elmhes, hqr), with bounded iterations */
int lcv_eigenvalues(double *a, int n, double *wr, double *wi);

#endif
