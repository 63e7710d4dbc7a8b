#include <deal.II/base/exceptions.h>

#include <immersed_grains/linear_algebra/component_block.h>
#include <immersed_grains/linear_algebra/restricted_schwarz_ilu.h>

#include <Epetra_CrsMatrix.h>
#include <Epetra_MultiVector.h>
#include <Ifpack.h>
#include <Ifpack_Preconditioner.h>
#include <Teuchos_ParameterList.hpp>

namespace ImmersedGrains
{
  namespace
  {
    Teuchos::RCP<Ifpack_Preconditioner>
    restricted_ilu(const Epetra_CrsMatrix &matrix, const unsigned int overlap)
    {
      Ifpack_Preconditioner *ilu =
        Ifpack().Create("ILU",
                        const_cast<Epetra_CrsMatrix *>(&matrix),
                        overlap);
      AssertThrow(ilu != nullptr,
                  dealii::ExcMessage("Ifpack could not create its ILU."));
      Teuchos::RCP<Ifpack_Preconditioner> owned = Teuchos::rcp(ilu);

      Teuchos::ParameterList parameters;
      parameters.set("fact: level-of-fill", 0);
      parameters.set("fact: absolute threshold", 0.);
      parameters.set("fact: relative threshold", 1.);
      parameters.set("schwarz: combine mode", "Zero");
      int error = ilu->SetParameters(parameters);
      AssertThrow(error == 0, dealii::LACExceptions::ExcTrilinosError(error));
      error = ilu->Initialize();
      AssertThrow(error == 0, dealii::LACExceptions::ExcTrilinosError(error));
      error = ilu->Compute();
      AssertThrow(error == 0, dealii::LACExceptions::ExcTrilinosError(error));
      return owned;
    }


    // An operator on vectors numbered like A = K (x) I_n's rows that
    // applies a preconditioner of K to each component, all components in
    // one multi-vector application, and divides the fixed unknowns by their
    // diagonal.
    class EachComponentOperator : public Epetra_Operator
    {
    public:
      EachComponentOperator(const ComponentBlock         &block,
                            Teuchos::RCP<Epetra_Operator> scalar)
          : block(block)
          , scalar(scalar)
          , source(block.scalar_matrix().RowMap(), block.n_components())
          , destination(block.scalar_matrix().RowMap(), block.n_components())
      {
      }

      int
      ApplyInverse(const Epetra_MultiVector &x,
                   Epetra_MultiVector       &y) const override
      {
        if (x.NumVectors() != 1 || y.NumVectors() != 1)
          return -1;
        block.split(x, source);
        const int error = scalar->ApplyInverse(source, destination);
        if (error != 0)
          return error;
        block.interleave(destination, x, y, true);
        return 0;
      }

      int
      Apply(const Epetra_MultiVector &, Epetra_MultiVector &) const override
      {
        return -1;
      }

      int
      SetUseTranspose(const bool use_transpose) override
      {
        return use_transpose ? -1 : 0;
      }

      double
      NormInf() const override
      {
        return 0;
      }

      const char *
      Label() const override
      {
        return "ILU(0) of each component";
      }

      bool
      UseTranspose() const override
      {
        return false;
      }

      bool
      HasNormInf() const override
      {
        return false;
      }

      const Epetra_Comm &
      Comm() const override
      {
        return block.component_map().Comm();
      }

      const Epetra_Map &
      OperatorDomainMap() const override
      {
        return block.component_map();
      }

      const Epetra_Map &
      OperatorRangeMap() const override
      {
        return block.component_map();
      }

    private:
      const ComponentBlock         &block;
      Teuchos::RCP<Epetra_Operator> scalar;
      mutable Epetra_MultiVector    source, destination;
    };
  } // namespace


  void
  RestrictedSchwarzILU::initialize(
    const dealii::TrilinosWrappers::SparseMatrix &matrix,
    const unsigned int                            overlap)
  {
    preconditioner.reset();
    preconditioner = restricted_ilu(matrix.trilinos_matrix(), overlap);
  }


  void
  RestrictedSchwarzILU::initialize(const ComponentBlock &block,
                                   const unsigned int    overlap)
  {
    preconditioner.reset();
    preconditioner = Teuchos::rcp(new EachComponentOperator(
      block, restricted_ilu(block.scalar_matrix(), overlap)));
  }

} // namespace ImmersedGrains
