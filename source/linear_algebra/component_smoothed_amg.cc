#include <deal.II/base/exceptions.h>

#include <immersed_grains/linear_algebra/component_block.h>
#include <immersed_grains/linear_algebra/component_smoothed_amg.h>

#include <Epetra_Map.h>
#include <Epetra_Vector.h>
#include <Teuchos_ParameterList.hpp>
#include <ml_MultiLevelPreconditioner.h>
#include <ml_include.h>

namespace ImmersedGrains
{
  namespace
  {
    // ML's smoother interface: the data pointer is the AMG object.
    int
    smooth_finest_level(ML_Smoother *smoother,
                        int /*n_in*/,
                        double *x,
                        int /*n_out*/,
                        double *rhs)
    {
      const auto *amg = static_cast<const ComponentSmoothedAMG *>(
        ML_Get_MySmootherData(smoother));
      amg->smooth(x, rhs, smoother->init_guess != ML_NONZERO);
      return 0;
    }
  } // namespace


  ComponentSmoothedAMG::ComponentSmoothedAMG() = default;


  // ML's finest-level smoother points at this object and its ILU: the base
  // class's destructor frees ML, which frees no smoother data it did not
  // make.
  ComponentSmoothedAMG::~ComponentSmoothedAMG() = default;


  void
  ComponentSmoothedAMG::initialize(
    const dealii::TrilinosWrappers::SparseMatrix &matrix,
    const ComponentBlock                         &component_block,
    const Teuchos::ParameterList                 &parameters,
    const unsigned int                            overlap)
  {
    block = nullptr;
    // At a slip wall K holds the wall's nodes as free in every component:
    // its ILU is then not A's, and as the finest smoother it left FGMRES
    // short of its tolerance on a 3D channel with slip faces
    // (tests/fluid_brinkman_poiseuille). ML's own smoother stays there.
    if (!component_block.components_fixed_alike())
    {
      dealii::TrilinosWrappers::PreconditionAMG::initialize(matrix, parameters);
      return;
    }
    Teuchos::ParameterList without_finest_smoother = parameters;
    without_finest_smoother.set("smoother: type (level 0)", "do-nothing");
    dealii::TrilinosWrappers::PreconditionAMG::initialize(
      matrix, without_finest_smoother);

    const auto &ml_preconditioner =
      dynamic_cast<const ML_Epetra::MultiLevelPreconditioner &>(
        trilinos_operator());
    ML *ml = const_cast<ML *>(ml_preconditioner.GetML());
    AssertThrow(ml != nullptr, dealii::ExcMessage("ML built no hierarchy."));
    // A single level is solved by ML's coarse solver alone: no smoother.
    if (ml->ML_num_actual_levels < 2)
      return;
    block = &component_block;
    fine_ilu.initialize(component_block, overlap);
    const Epetra_Map &rows = component_block.component_map();
    residual               = std::make_unique<Epetra_Vector>(rows);
    correction             = std::make_unique<Epetra_Vector>(rows);
    char      name[]       = "component ILU";
    const int error =
      ML_Set_Smoother(ml, 0, ML_BOTH, this, &smooth_finest_level, name);
    AssertThrow(error == 0,
                dealii::ExcMessage("ML did not take the finest smoother."));
  }


  bool
  ComponentSmoothedAMG::smooths_through_components() const
  {
    return block != nullptr;
  }


  void
  ComponentSmoothedAMG::smooth(double       *x,
                               const double *rhs,
                               const bool    zero_guess) const
  {
    const Epetra_Map   &rows = block->component_map();
    Epetra_Vector       solution(View, rows, x);
    const Epetra_Vector right_hand_side(View, rows, const_cast<double *>(rhs));
    const Epetra_Operator &ilu = fine_ilu.trilinos_operator();
    if (zero_guess)
    {
      ilu.ApplyInverse(right_hand_side, solution);
      return;
    }
    block->vmult(*residual, solution);
    residual->Update(1.0, right_hand_side, -1.0);
    ilu.ApplyInverse(*residual, *correction);
    solution.Update(1.0, *correction, 1.0);
  }
} // namespace ImmersedGrains
