//! Forward kinematics of many configurations at once: [`BatchedChain`] runs [`LANES`]
//! configurations side by side, each matrix entry a `[Real; N]`, so every step is a loop
//! over lanes that the compiler vectorises (no intrinsics; the one `unsafe` is the call of
//! the copy compiled for AVX2 once the processor is known to have it).
//!
//! The chain is taken in aligned frames (each joint's axis turned onto z, as
//! [`super::AlignedChain`] does), so a joint costs one constant rotation product and a
//! two-column turn; where the constant is a signed permutation (most joints of the shipped
//! arms) the product is only a choice of columns, its signs put on the sine and cosine. Sines and cosines are computed per lane by the polynomials of fdlibm's
//! kernels (within an ulp or two of the platform's), the angle reduced by a two-part π/2.
//! Lanes never mix: a configuration's result does not depend on the others in its group, so
//! any split of a batch gives the same bits.

use super::error::KinematicsError;
use super::spaces::{CpsaState, cpsa_from_points};
use crate::math::{DOF, Matrix3, PI, Real, Rotation3, Vector3};

const FRAC_2_PI: Real = std::f64::consts::FRAC_2_PI;
use crate::robot::Robot;

/// Configurations computed side by side: eight, two AVX2 registers to a value, so that the
/// processor has two independent chains of products to interleave (criterion, 1,000 rows,
/// iiwa14, the shared 2-core x86_64 machine: hand frames 47.8 -> 32.4 µs, CPSA values
/// 74.6 -> 60.6 µs against four lanes; a copy for AVX-512, one register to a value, was slower
/// than this, 38 µs for the hand frames).
pub const LANES: usize = 8;

/// Values per row of the batched results: a 4x4 frame, a 6x7 Jacobian.
pub const FRAME_VALUES: usize = 16;
/// Values per row of a batched J_ge.
pub const JACOBIAN_VALUES: usize = 6 * DOF;

/// One value per lane.
type Lane<const N: usize> = [Real; N];
/// A 3-vector per lane.
type LaneVector<const N: usize> = [Lane<N>; 3];
/// A 3x3 matrix per lane, `m[row][column]`.
type LaneMatrix<const N: usize> = [[Lane<N>; 3]; 3];

/// One joint of the aligned chain: the constant transform from the parent's aligned frame to
/// this joint's, before the turn about z.
#[derive(Debug, Clone, Copy)]
struct Step {
    rotation: Constant,
    translation: Offset,
}

/// A constant rotation of the chain. Most joint frames of the shipped arms are turned by 0 or
/// ±π/2, which makes the rotation a signed permutation: a product by it is then a choice of
/// columns and sign flips instead of 27 products and 18 sums per lane group.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Constant {
    /// Column j of `m c` is `sign[j]` times column `source[j]` of `m`.
    Permutation { source: [usize; 3], sign: [Real; 3] },
    /// Any other rotation, row-major.
    General([[Real; 3]; 3]),
}

/// Entries this close to 0 or ±1 are taken as exactly that: the rounding of a ±π/2 turn
/// (cos(π/2) is 6.1e-17 in doubles) and of the aligning products, a few ulps. Taking them as
/// exact moves a product by at most 3 · SNAP of its size, far below the 1e-12 the batched rows
/// promise.
const SNAP: Real = 4.0 * Real::EPSILON;

impl Constant {
    /// `c` as a signed permutation if each column has one entry within [`SNAP`] of ±1 and the
    /// others within [`SNAP`] of 0, in different rows; else as it is.
    fn of(c: &[[Real; 3]; 3]) -> Self {
        let mut source = [0; 3];
        let mut sign = [0.0; 3];
        let mut used = [false; 3];
        for j in 0..3 {
            let unit: Vec<usize> =
                (0..3).filter(|&r| (c[r][j].abs() - 1.0).abs() <= SNAP).collect();
            let zeros = (0..3).filter(|&r| c[r][j].abs() <= SNAP).count();
            match unit[..] {
                [r] if zeros == 2 && !used[r] => {
                    used[r] = true;
                    source[j] = r;
                    sign[j] = c[r][j].signum();
                }
                _ => return Self::General(*c),
            }
        }
        Self::Permutation { source, sign }
    }

    /// `m c`.
    #[inline(always)]
    fn times<const N: usize>(&self, m: &LaneMatrix<N>) -> LaneMatrix<N> {
        match self {
            Self::Permutation { source, sign } => std::array::from_fn(|i| {
                std::array::from_fn(|j| m[i][source[j]].map(|v| v * sign[j]))
            }),
            Self::General(c) => times_constant(m, c),
        }
    }
}

/// `t` (m) with the components within [`SNAP`] of its size, or under [`SNAP`] metres (a
/// femtometre: the residue of turning an offset along an axis by a rounded ±π/2), taken as 0,
/// which [`apply`] skips.
fn snapped(t: [Real; 3]) -> [Real; 3] {
    let size = t.iter().fold(1.0, |a: Real, v| a.max(v.abs()));
    t.map(|v| if v.abs() <= SNAP * size { 0.0 } else { v })
}

/// A constant offset of the chain by its nonzero components (the shipped arms' offsets mostly
/// lie along one axis of their frame), so that [`apply`] multiplies only those, in a branch
/// chosen once per joint and group rather than a loop over the components.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Offset {
    Zero,
    /// Component `.0` of value `.1`, the others 0.
    One(usize, Real),
    /// Two components (index, value), in index order, the third 0.
    Two([(usize, Real); 2]),
    /// Every component nonzero.
    Three([Real; 3]),
}

impl Offset {
    fn of(v: [Real; 3]) -> Self {
        let nonzero: Vec<(usize, Real)> =
            v.iter().copied().enumerate().filter(|(_, value)| *value != 0.0).collect();
        match nonzero[..] {
            [] => Self::Zero,
            [(r, value)] => Self::One(r, value),
            [a, b] => Self::Two([a, b]),
            _ => Self::Three(v),
        }
    }
}

/// The robot's chain prepared for [`LANES`] configurations at a time.
///
/// Batched results pair rows as `Iterator::zip` does: `q` holds rows of 7 joint values
/// (row-major), each output its rows; the shorter of the two sets the count.
#[derive(Debug, Clone)]
pub struct BatchedChain {
    steps: [Step; DOF],
    /// E in aligned frame 3.
    elbow: Offset,
    /// W in aligned frame 6.
    wrist: Offset,
    /// Ow from aligned frame 7: the hand's rotation in that frame.
    hand: Constant,
    /// The robot's vertical z_b, for the swivel angle.
    vertical: Vector3,
}

/// What forward kinematics gives for one group of lanes, in {b}.
struct GroupPose<const N: usize> {
    /// The joint axes.
    axes: [LaneVector<N>; DOF],
    /// The linear rows of J_ge: W's velocity per unit rate of each joint.
    linear: [LaneVector<N>; DOF],
    elbow: LaneVector<N>,
    wrist: LaneVector<N>,
    /// Ow.
    hand: LaneMatrix<N>,
    /// θsw where asked for and regular (see [`swivels`]).
    swivel: [Option<Real>; N],
}

/// A rotation whose z column is `axis`, its x and y from a cross product with the basis
/// vector farthest from the axis: orthonormal to an ulp whatever the axis (nalgebra's
/// `rotation_between` takes the angle by acos, which loses half the digits of an axis a few
/// microradians off z, as URDFs exported with rounding have).
fn aligning(axis: &Vector3) -> Matrix3 {
    let z = axis.normalize();
    let helper = if z.x.abs() < 0.9 { Vector3::x() } else { Vector3::y() };
    let y = z.cross(&helper).normalize();
    Matrix3::from_columns(&[y.cross(&z), y, z])
}

fn rows_of(m: &Matrix3) -> [[Real; 3]; 3] {
    std::array::from_fn(|i| std::array::from_fn(|j| m[(i, j)]))
}

fn values_of(v: &Vector3) -> [Real; 3] {
    [v.x, v.y, v.z]
}

impl BatchedChain {
    /// The chain of `robot`.
    pub fn new(robot: &Robot) -> Self {
        Self::from_constants(robot, Constant::of, |t| Offset::of(snapped(t)))
    }

    /// The chain of `robot` with every constant a [`Constant::General`] product and no
    /// component skipped: the slow exact kernel the specialised one is tested against.
    #[cfg(test)]
    fn general(robot: &Robot) -> Self {
        Self::from_constants(robot, |c| Constant::General(*c), Offset::Three)
    }

    /// The chain, its rotations taken by `rotation` and its offsets by `offset`.
    fn from_constants(
        robot: &Robot,
        rotation: impl Fn(&[[Real; 3]; 3]) -> Constant,
        offset: impl Fn([Real; 3]) -> Offset,
    ) -> Self {
        let align: [Matrix3; DOF] = std::array::from_fn(|k| aligning(&robot.joints[k].axis));
        // A_{k-1}ᵀ for frame k, the identity for {b}.
        let aligned_from_frame =
            |k: usize| if k == 0 { Matrix3::identity() } else { align[k - 1].transpose() };
        let steps = std::array::from_fn(|k| {
            let p = &robot.joints[k].parent_from_joint;
            let before = aligned_from_frame(k);
            Step {
                rotation: rotation(&rows_of(&(before * p.rotation.matrix() * align[k]))),
                translation: offset(values_of(&(before * p.translation.vector))),
            }
        });
        let s = &robot.structure;
        Self {
            steps,
            elbow: offset(values_of(&(aligned_from_frame(3) * s.elbow_in_frame3))),
            wrist: offset(values_of(&(aligned_from_frame(6) * s.wrist_in_frame6))),
            hand: rotation(&rows_of(&(aligned_from_frame(DOF) * robot.frame7_from_hand.matrix()))),
            vertical: robot.vertical,
        }
    }

    /// The hand frame {W} (row-major 4x4: Ow and W) at each row of `q`.
    pub fn hand_frames(&self, q: &[Real], frames: &mut [Real]) {
        let rows = frames.chunks_exact_mut(FRAME_VALUES);
        self.each_group::<false, false, _>(q, rows, |pose, lane, frame| {
            write_frame(frame, pose, lane)
        });
    }

    /// J_ge (row-major 6x7, as [`super::geometric_jacobian`]) at each row of `q`.
    pub fn jacobians(&self, q: &[Real], jacobians: &mut [Real]) {
        let rows = jacobians.chunks_exact_mut(JACOBIAN_VALUES);
        self.each_group::<true, false, _>(q, rows, |pose, lane, j| write_jacobian(j, pose, lane));
    }

    /// The hand frame and J_ge at each row of `q`, from one forward kinematics.
    pub fn hand_frames_and_jacobians(
        &self,
        q: &[Real],
        frames: &mut [Real],
        jacobians: &mut [Real],
    ) {
        let rows =
            frames.chunks_exact_mut(FRAME_VALUES).zip(jacobians.chunks_exact_mut(JACOBIAN_VALUES));
        self.each_group::<true, false, _>(q, rows, |pose, lane, (frame, j)| {
            write_frame(frame, pose, lane);
            write_jacobian(j, pose, lane);
        });
    }

    /// The hand frame {W} (row-major 4x4) at one configuration, by the batched steps on a
    /// single lane: for a caller with one configuration at a time, to whom a group would
    /// compute seven other rows for nothing. The bits of that row in any batch.
    pub fn hand_frame(&self, q: &[Real; DOF], frame: &mut [Real; FRAME_VALUES]) {
        let pose = self.group_pose::<1, false, false>(&q.map(|v| [v]));
        write_frame(frame, &pose, 0);
    }

    /// The hand frame and J_ge at one configuration, as [`Self::hand_frame`]: the bits of that
    /// row of [`Self::hand_frames_and_jacobians`].
    pub fn hand_frame_and_jacobian(
        &self,
        q: &[Real; DOF],
        frame: &mut [Real; FRAME_VALUES],
        jacobian: &mut [Real; JACOBIAN_VALUES],
    ) {
        let pose = self.group_pose::<1, true, false>(&q.map(|v| [v]));
        write_frame(frame, &pose, 0);
        write_jacobian(jacobian, &pose, 0);
    }

    /// The CPSA state at each row of `q`, as [`super::cpsa_state`] gives it; `states` is
    /// called with each row's index and result, in order.
    pub fn cpsa_states(
        &self,
        robot: &Robot,
        q: &[Real],
        mut states: impl FnMut(usize, Result<CpsaState, KinematicsError>),
    ) {
        let rows = q.len() / DOF;
        self.each_group::<false, true, _>(q, 0..rows, |pose, lane, row| {
            let point = |v: &LaneVector<LANES>| Vector3::new(v[0][lane], v[1][lane], v[2][lane]);
            let hand = Matrix3::from_fn(|i, j| pose.hand[i][j][lane]);
            let hand = Rotation3::from_matrix_unchecked(hand);
            let state = match pose.swivel[lane] {
                Some(swivel) => Ok(CpsaState { pw: point(&pose.wrist), ow: hand, swivel }),
                None => cpsa_from_points(robot, &point(&pose.elbow), &point(&pose.wrist), hand),
            };
            states(row, state);
        });
    }

    /// The CPSA state of each row of `q`, as [`Self::cpsa_states`] gives it, written as values:
    /// `pw` 3 a row, `ow` 9 a row (row-major), `swivel` 1 a row. A regular row is copied from
    /// its lanes without making a [`CpsaState`]; the first failing row is returned with its
    /// error, and no row after it is written.
    pub fn cpsa_values(
        &self,
        robot: &Robot,
        q: &[Real],
        pw: &mut [Real],
        ow: &mut [Real],
        swivel: &mut [Real],
    ) -> Option<(usize, KinematicsError)> {
        let outputs = pw.chunks_exact_mut(3).zip(ow.chunks_exact_mut(9)).zip(swivel.iter_mut());
        let mut failed = None;
        self.each_group::<false, true, _>(q, outputs.enumerate(), |pose, lane, (row, out)| {
            if failed.is_some() {
                return;
            }
            let ((pw, ow), swivel) = out;
            let hand = &pose.hand;
            if let Some(angle) = pose.swivel[lane] {
                for i in 0..3 {
                    pw[i] = pose.wrist[i][lane];
                    for j in 0..3 {
                        ow[3 * i + j] = hand[i][j][lane];
                    }
                }
                *swivel = angle;
                return;
            }
            // Near a singularity: cpsa_from_points decides, by its own tolerances.
            let point = |v: &LaneVector<LANES>| Vector3::new(v[0][lane], v[1][lane], v[2][lane]);
            let hand = Rotation3::from_matrix_unchecked(Matrix3::from_fn(|i, j| hand[i][j][lane]));
            match cpsa_from_points(robot, &point(&pose.elbow), &point(&pose.wrist), hand) {
                Ok(state) => {
                    pw.copy_from_slice(state.pw.as_slice());
                    for i in 0..3 {
                        for j in 0..3 {
                            ow[3 * i + j] = state.ow[(i, j)];
                        }
                    }
                    *swivel = state.swivel;
                }
                Err(e) => failed = Some((row, e)),
            }
        });
        failed
    }

    /// Runs `each(pose, lane, out)` for every row of `q` paired with an item of `outputs`,
    /// [`LANES`] rows at a time; a last short group repeats its last row in the spare lanes.
    ///
    /// On x86_64 processors with AVX2 the loop runs as a copy compiled for them (four lanes
    /// to an instruction instead of two); both copies do the same operations in the same
    /// order (Rust never fuses a multiply and an add on its own), so the bits are the same.
    /// `LINEAR`: whether the pose needs J_ge's linear rows (left zero otherwise); `SWIVEL`:
    /// whether it needs the swivel angles (else `None`).
    #[inline(always)]
    fn each_group<const LINEAR: bool, const SWIVEL: bool, O>(
        &self,
        q: &[Real],
        outputs: impl IntoIterator<Item = O>,
        each: impl FnMut(&GroupPose<LANES>, usize, O),
    ) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the processor has AVX2, checked on the line above.
            #[allow(unsafe_code)]
            unsafe {
                return self.each_group_avx2::<LINEAR, SWIVEL, O>(q, outputs, each);
            }
        }
        self.each_group_portable::<LINEAR, SWIVEL, O>(q, outputs, each);
    }

    /// [`Self::each_group`] compiled for AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn each_group_avx2<const LINEAR: bool, const SWIVEL: bool, O>(
        &self,
        q: &[Real],
        outputs: impl IntoIterator<Item = O>,
        each: impl FnMut(&GroupPose<LANES>, usize, O),
    ) {
        self.each_group_portable::<LINEAR, SWIVEL, O>(q, outputs, each);
    }

    /// [`Self::each_group`] for any processor; inlined into the AVX2 copy.
    #[inline(always)]
    fn each_group_portable<const LINEAR: bool, const SWIVEL: bool, O>(
        &self,
        q: &[Real],
        outputs: impl IntoIterator<Item = O>,
        mut each: impl FnMut(&GroupPose<LANES>, usize, O),
    ) {
        let mut outputs = outputs.into_iter();
        for group in q.chunks(DOF * LANES) {
            let rows = group.len() / DOF;
            if rows == 0 {
                return;
            }
            let mut joints = [[0.0; LANES]; DOF];
            for (l, lane) in (0..LANES).map(|l| (l, l.min(rows - 1))) {
                for k in 0..DOF {
                    joints[k][l] = group[DOF * lane + k];
                }
            }
            let pose = self.group_pose::<LANES, LINEAR, SWIVEL>(&joints);
            for lane in 0..rows {
                let Some(out) = outputs.next() else { return };
                each(&pose, lane, out);
            }
        }
    }

    /// Forward kinematics of one group: `joints[k]` holds joint k's value in each lane; J_ge's
    /// linear rows only when `LINEAR` (the frames and CPSA states do not read them).
    #[inline(always)]
    fn group_pose<const N: usize, const LINEAR: bool, const SWIVEL: bool>(
        &self,
        joints: &[Lane<N>; DOF],
    ) -> GroupPose<N> {
        let mut rotation: LaneMatrix<N> = [[[0.0; N]; 3]; 3];
        for (i, row) in rotation.iter_mut().enumerate() {
            row[i] = [1.0; N];
        }
        let mut translation: LaneVector<N> = [[0.0; N]; 3];
        let mut axes = [[[0.0; N]; 3]; DOF];
        let mut axis_points = [[[0.0; N]; 3]; DOF];
        let (mut elbow, mut wrist) = ([[0.0; N]; 3], [[0.0; N]; 3]);
        for (k, step) in self.steps.iter().enumerate() {
            translation = apply(&rotation, &step.translation, &translation);
            let (sin, cos) = sin_cos(&joints[k]);
            rotation = match &step.rotation {
                Constant::Permutation { source, sign } => {
                    turned_permutation(&rotation, source, sign, &sin, &cos)
                }
                Constant::General(c) => turned(&times_constant(&rotation, c), &sin, &cos),
            };
            for i in 0..3 {
                axes[k][i] = rotation[i][2];
            }
            axis_points[k] = translation;
            // E rides on frame 3, W on frame 6.
            if k == 2 {
                elbow = apply(&rotation, &self.elbow, &translation);
            } else if k == 5 {
                wrist = apply(&rotation, &self.wrist, &translation);
            }
        }
        // W's velocity per unit rate of each joint: z_k × (W - p_k); joint 7 cannot move W,
        // which rides on frame 6.
        let mut linear = [[[0.0; N]; 3]; DOF];
        for k in (0..DOF - 1).filter(|_| LINEAR) {
            let (z, p) = (&axes[k], &axis_points[k]);
            for l in 0..N {
                let d = [wrist[0][l] - p[0][l], wrist[1][l] - p[1][l], wrist[2][l] - p[2][l]];
                linear[k][0][l] = z[1][l] * d[2] - z[2][l] * d[1];
                linear[k][1][l] = z[2][l] * d[0] - z[0][l] * d[2];
                linear[k][2][l] = z[0][l] * d[1] - z[1][l] * d[0];
            }
        }
        let swivel = if SWIVEL { swivels(&elbow, &wrist, &self.vertical) } else { [None; N] };
        GroupPose { axes, linear, elbow, wrist, hand: self.hand.times(&rotation), swivel }
    }
}

/// Below this sine of the elbow angle, or distance (m) of W from the vertical through S, a
/// lane is left to [`cpsa_from_points`], which decides the singularity by its own tolerances
/// (1e-9, a thousand times smaller): near them, rounding could tip the decision.
const REGULAR: Real = 1e-6;

#[inline(always)]
fn norm(v: &[Real; 3]) -> Real {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

#[inline(always)]
fn cross(a: &[Real; 3], b: &[Real; 3]) -> [Real; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

#[inline(always)]
fn dot(a: &[Real; 3], b: &[Real; 3]) -> Real {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// θsw of each lane, side by side, by [`cpsa_from_points`]'s formula (the triangle S = 0, E,
/// W: l the unit normal of its plane, n that of the vertical plane through W, θsw =
/// atan2(-(n × l)·x, n·l) with x along W); `None` for a lane near a singularity.
///
/// atan2 takes only the ratio of its arguments, so the normals are left unnormalised
/// (ew × e for l, z_b × W for n) and their lengths cancel: θsw = atan2(-(m × v)·W, (m·v)|W|).
/// One square root a lane instead of six roots and fifteen divisions; the same angle to a few
/// ulps, not the same bits.
#[inline(always)]
fn swivels<const N: usize>(
    elbow: &LaneVector<N>,
    wrist: &LaneVector<N>,
    vertical: &Vector3,
) -> [Option<Real>; N] {
    let vertical = values_of(vertical);
    let (mut a, mut b, mut regular) = ([0.0; N], [0.0; N], [false; N]);
    for l in 0..N {
        let e = [elbow[0][l], elbow[1][l], elbow[2][l]];
        let w = [wrist[0][l], wrist[1][l], wrist[2][l]];
        let ew = [w[0] - e[0], w[1] - e[1], w[2] - e[2]];
        let v = cross(&ew, &e);
        let m = cross(&vertical, &w);
        a[l] = -dot(&cross(&m, &v), &w);
        b[l] = dot(&m, &v) * norm(&w);
        // The sine of the elbow angle, |v| / (|ew| |e|), and |m| against REGULAR, squared.
        // Written so that a NaN is not regular.
        let square = REGULAR * REGULAR;
        regular[l] = dot(&v, &v) >= square * dot(&ew, &ew) * dot(&e, &e) && dot(&m, &m) >= square;
    }
    let angle = atan2(&a, &b);
    std::array::from_fn(|l| regular[l].then_some(angle[l]))
}

/// atan2(y, x) of each lane by fdlibm's atan polynomial, side by side: |y|/|x| is reduced to
/// one of fdlibm's five ranges in a single division of its |y| and |x| combination (not
/// fdlibm's bits, within a few ulps of them), then put in its quadrant. A lane with y and x
/// both zero, or not finite, is left to the platform's atan2.
#[allow(clippy::excessive_precision)] // fdlibm's digits as published: the same doubles.
#[inline(always)]
fn atan2<const N: usize>(y: &Lane<N>, x: &Lane<N>) -> Lane<N> {
    const ATAN_HIGH: [Real; 4] = [
        4.636_476_090_008_060_935_15e-1,
        std::f64::consts::FRAC_PI_4,
        9.827_937_232_473_290_540_82e-1,
        std::f64::consts::FRAC_PI_2,
    ];
    const ATAN_LOW: [Real; 4] = [
        2.269_877_745_296_168_709_24e-17,
        3.061_616_997_868_383_017_93e-17,
        1.390_331_103_123_099_845_16e-17,
        6.123_233_995_736_766_035_87e-17,
    ];
    const AT: [Real; 11] = [
        3.333_333_333_333_293_180_27e-1,
        -1.999_999_999_987_648_324_76e-1,
        1.428_571_427_250_346_637_11e-1,
        -1.111_111_040_546_235_578_80e-1,
        9.090_887_133_436_506_561_96e-2,
        -7.691_876_205_044_829_994_95e-2,
        6.661_073_137_387_531_206_69e-2,
        -5.833_570_133_790_573_486_45e-2,
        4.976_877_994_615_932_360_17e-2,
        -3.653_157_274_421_691_552_70e-2,
        1.628_582_011_536_578_236_23e-2,
    ];
    const PI_LOW: Real = 1.224_646_799_147_353_177_2e-16;
    let mut out = [0.0; N];
    let mut special = false;
    for l in 0..N {
        let (a, b) = (y[l].abs(), x[l].abs());
        // t = a / b, reduced as fdlibm's atan does: t, (2t - 1)/(2 + t), (t - 1)/(t + 1),
        // (t - 1.5)/(1 + 1.5t) or -1/t by its range, each written over a and b. Every
        // candidate is computed and one chosen by selects, not branches, so that the lanes
        // run side by side; the first range's atan(t) = t - t s is written 0 - ((t s - 0) - t),
        // the same value (a rounded difference is symmetric), its zero's sign set below.
        let (mut num, mut den, mut high, mut low) = (-b, a, ATAN_HIGH[3], ATAN_LOW[3]);
        let ranges = [
            (2.4375, a - 1.5 * b, b + 1.5 * a, ATAN_HIGH[2], ATAN_LOW[2]),
            (1.1875, a - b, a + b, ATAN_HIGH[1], ATAN_LOW[1]),
            (0.6875, 2.0 * a - b, 2.0 * b + a, ATAN_HIGH[0], ATAN_LOW[0]),
            (0.4375, a, b, 0.0, 0.0),
        ];
        for (bound, n, d, h, lo) in ranges {
            let below = a < bound * b;
            num = if below { n } else { num };
            den = if below { d } else { den };
            high = if below { h } else { high };
            low = if below { lo } else { low };
        }
        let t = num / den;
        let z = t * t;
        let w = z * z;
        let s1 = z * (AT[0] + w * (AT[2] + w * (AT[4] + w * (AT[6] + w * (AT[8] + w * AT[10])))));
        let s2 = w * (AT[1] + w * (AT[3] + w * (AT[5] + w * (AT[7] + w * AT[9]))));
        let angle = high - ((t * (s1 + s2) - low) - t);
        let angle = if x[l].is_sign_negative() { PI - (angle - PI_LOW) } else { angle };
        out[l] = angle.copysign(y[l]);
        special |= !((a > 0.0 || b > 0.0) && a.is_finite() && b.is_finite());
    }
    // Both zero, or not finite: the platform's, lane by lane (rare).
    if special {
        for l in 0..N {
            let (a, b) = (y[l].abs(), x[l].abs());
            if !((a > 0.0 || b > 0.0) && a.is_finite() && b.is_finite()) {
                out[l] = y[l].atan2(x[l]);
            }
        }
    }
    out
}

/// `m` turned about its z column by the angle of (sin, cos) in each lane: `m Rz(θ)`.
#[inline(always)]
fn turned<const N: usize>(m: &LaneMatrix<N>, sin: &Lane<N>, cos: &Lane<N>) -> LaneMatrix<N> {
    let mut out = *m;
    for i in 0..3 {
        let (x, y) = (&m[i][0], &m[i][1]);
        for l in 0..N {
            out[i][0][l] = x[l] * cos[l] + y[l] * sin[l];
            out[i][1][l] = y[l] * cos[l] - x[l] * sin[l];
        }
    }
    out
}

/// [`turned`] of `m c` for a signed permutation c (column j of `m c` is `sign[j]` times column
/// `source[j]` of m), without forming `m c`: the signs go onto the sine and cosine instead
/// of onto 36 entries. A product by ±1 is exact and rounding is symmetric in sign, so
/// `(±x) cos = x (±cos)` to the bit: the same values as `turned(&c.times(m), ..)`.
#[inline(always)]
fn turned_permutation<const N: usize>(
    m: &LaneMatrix<N>,
    source: &[usize; 3],
    sign: &[Real; 3],
    sin: &Lane<N>,
    cos: &Lane<N>,
) -> LaneMatrix<N> {
    // One copy per permutation, its columns known at compile time, so that the rotation can
    // stay in registers instead of being indexed in memory.
    match *source {
        [0, 1, 2] => turned_columns::<N, 0, 1, 2>(m, sign, sin, cos),
        [0, 2, 1] => turned_columns::<N, 0, 2, 1>(m, sign, sin, cos),
        [1, 0, 2] => turned_columns::<N, 1, 0, 2>(m, sign, sin, cos),
        [1, 2, 0] => turned_columns::<N, 1, 2, 0>(m, sign, sin, cos),
        [2, 0, 1] => turned_columns::<N, 2, 0, 1>(m, sign, sin, cos),
        _ => turned_columns::<N, 2, 1, 0>(m, sign, sin, cos),
    }
}

/// [`turned_permutation`] for the permutation (X, Y, Z).
#[inline(always)]
fn turned_columns<const N: usize, const X: usize, const Y: usize, const Z: usize>(
    m: &LaneMatrix<N>,
    sign: &[Real; 3],
    sin: &Lane<N>,
    cos: &Lane<N>,
) -> LaneMatrix<N> {
    let signed = |v: &Lane<N>, s: Real| v.map(|x| x * s);
    let (cos_x, sin_x) = (signed(cos, sign[0]), signed(sin, sign[0]));
    let (cos_y, sin_y) = (signed(cos, sign[1]), signed(sin, sign[1]));
    let mut out = [[[0.0; N]; 3]; 3];
    for i in 0..3 {
        let (x, y, z) = (&m[i][X], &m[i][Y], &m[i][Z]);
        for l in 0..N {
            out[i][0][l] = x[l] * cos_x[l] + y[l] * sin_y[l];
            out[i][1][l] = y[l] * cos_y[l] - x[l] * sin_x[l];
            out[i][2][l] = z[l] * sign[2];
        }
    }
    out
}

/// `m c` with c the same in every lane.
#[inline(always)]
fn times_constant<const N: usize>(m: &LaneMatrix<N>, c: &[[Real; 3]; 3]) -> LaneMatrix<N> {
    let mut out = [[[0.0; N]; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            for l in 0..N {
                out[i][j][l] = m[i][0][l] * c[0][j] + m[i][1][l] * c[1][j] + m[i][2][l] * c[2][j];
            }
        }
    }
    out
}

/// `m v + t` with v the same in every lane, its zero components skipped: with m finite a
/// skipped term is ±0, which changes no sum but the sign of a zero. The terms are summed in
/// index order, then added to t.
#[inline(always)]
fn apply<const N: usize>(m: &LaneMatrix<N>, v: &Offset, t: &LaneVector<N>) -> LaneVector<N> {
    let mut out = *t;
    // The match outside the loops, so that each arm is a straight run of lane products.
    match *v {
        Offset::Zero => {}
        Offset::One(r, a) => {
            for i in 0..3 {
                for l in 0..N {
                    out[i][l] += m[i][r][l] * a;
                }
            }
        }
        Offset::Two([(r, a), (s, b)]) => {
            for i in 0..3 {
                for l in 0..N {
                    out[i][l] += m[i][r][l] * a + m[i][s][l] * b;
                }
            }
        }
        Offset::Three([a, b, c]) => {
            for i in 0..3 {
                for l in 0..N {
                    out[i][l] += m[i][0][l] * a + m[i][1][l] * b + m[i][2][l] * c;
                }
            }
        }
    }
    out
}

/// Lane `lane`'s hand frame {W} as a row-major 4x4 homogeneous matrix.
#[inline(always)]
fn write_frame<const N: usize>(out: &mut [Real], pose: &GroupPose<N>, lane: usize) {
    let out = &mut out[..FRAME_VALUES];
    for i in 0..3 {
        for j in 0..3 {
            out[4 * i + j] = pose.hand[i][j][lane];
        }
        out[4 * i + 3] = pose.wrist[i][lane];
    }
    out[12..16].copy_from_slice(&[0.0, 0.0, 0.0, 1.0]);
}

/// Lane `lane`'s J_ge, row-major: W's velocity (rows 0-2), the hand's angular velocity (3-5).
#[inline(always)]
fn write_jacobian<const N: usize>(out: &mut [Real], pose: &GroupPose<N>, lane: usize) {
    let out = &mut out[..JACOBIAN_VALUES];
    for i in 0..3 {
        for k in 0..DOF {
            out[DOF * i + k] = pose.linear[k][i][lane];
            out[DOF * (i + 3) + k] = pose.axes[k][i][lane];
        }
    }
}

/// Past this |angle| (rad) the two-part reduction loses bits: the platform's sin_cos then.
const REDUCTION_LIMIT: Real = 1.0e5;
/// 1.5 · 2^52: adding and subtracting it rounds to the nearest integer, the integer's low
/// bits landing in the low bits of the sum.
const ROUNDER: Real = 6_755_399_441_055_744.0;
/// π/2 in two parts (fdlibm's pio2_1, pio2_1t): the first has 33 bits, so j · it is exact.
#[allow(clippy::excessive_precision)] // fdlibm's digits as published: the same doubles.
const FRAC_PI_2_HIGH: Real = 1.570_796_326_734_125_614_17;
#[allow(clippy::excessive_precision)] // fdlibm's digits as published: the same doubles.
const FRAC_PI_2_LOW: Real = 6.077_100_506_506_192_249_32e-11;

/// Sine and cosine of each lane.
#[inline(always)]
fn sin_cos<const N: usize>(x: &Lane<N>) -> (Lane<N>, Lane<N>) {
    if x.iter().all(|v| v.abs() <= REDUCTION_LIMIT) {
        reduced_sin_cos(x)
    } else {
        let pairs = x.map(Real::sin_cos);
        (pairs.map(|p| p.0), pairs.map(|p| p.1))
    }
}

/// Sine and cosine for |x| ≤ [`REDUCTION_LIMIT`]: x = jπ/2 + y with |y| ≤ π/4, fdlibm's
/// kernels at y, then the quadrant j mod 4 swaps and signs them.
#[inline(always)]
fn reduced_sin_cos<const N: usize>(x: &Lane<N>) -> (Lane<N>, Lane<N>) {
    let mut shifted = [0.0; N];
    for l in 0..N {
        shifted[l] = x[l] * FRAC_2_PI + ROUNDER;
    }
    let mut sin = [0.0; N];
    let mut cos = [0.0; N];
    for l in 0..N {
        let j = shifted[l] - ROUNDER;
        let y = (x[l] - j * FRAC_PI_2_HIGH) - j * FRAC_PI_2_LOW;
        let (s, c) = (kernel_sin(y), kernel_cos(y));
        let quadrant = shifted[l].to_bits() & 3;
        let (s, c) = if quadrant & 1 == 1 { (c, s) } else { (s, c) };
        // Quadrants 2, 3 negate the sine; 1, 2 the cosine.
        sin[l] = Real::from_bits(s.to_bits() ^ ((quadrant & 2) << 62));
        cos[l] = Real::from_bits(c.to_bits() ^ (((quadrant + 1) & 2) << 62));
    }
    (sin, cos)
}

/// sin y for |y| ≤ π/4 (fdlibm's __kernel_sin, no tail).
#[allow(clippy::excessive_precision)] // fdlibm's digits as published: the same doubles.
#[inline(always)]
fn kernel_sin(y: Real) -> Real {
    const S1: Real = -1.666_666_666_666_663_243_48e-1;
    const S2: Real = 8.333_333_333_322_489_461_24e-3;
    const S3: Real = -1.984_126_982_985_794_931_34e-4;
    const S4: Real = 2.755_731_370_707_006_767_89e-6;
    const S5: Real = -2.505_076_025_340_686_341_95e-8;
    const S6: Real = 1.589_690_995_211_550_102_21e-10;
    let z = y * y;
    let w = z * z;
    let r = S2 + z * (S3 + z * S4) + z * w * (S5 + z * S6);
    y + z * y * (S1 + z * r)
}

/// cos y for |y| ≤ π/4 (fdlibm's __kernel_cos, no tail).
#[allow(clippy::excessive_precision)] // fdlibm's digits as published: the same doubles.
#[inline(always)]
fn kernel_cos(y: Real) -> Real {
    const C1: Real = 4.166_666_666_666_660_190_37e-2;
    const C2: Real = -1.388_888_888_887_410_957_49e-3;
    const C3: Real = 2.480_158_728_947_672_941_78e-5;
    const C4: Real = -2.755_731_435_139_066_330_35e-7;
    const C5: Real = 2.087_572_321_298_174_827_90e-9;
    const C6: Real = -1.135_964_755_778_819_482_65e-11;
    let z = y * y;
    let w = z * z;
    let r = z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * C6));
    let half = 0.5 * z;
    let one_minus = 1.0 - half;
    one_minus + (((1.0 - one_minus) - half) + z * r)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::{arm_pose, cpsa_state, geometric_jacobian};
    use crate::math::PI;

    const ROBOTS: [&str; 6] =
        ["iiwa14", "panda", "centauro_right_arm", "coman_right_arm", "human_arm", "swivel_map_arm"];

    fn robot(name: &str) -> Robot {
        let path = format!("{}/../../robots/{name}.urdf", env!("CARGO_MANIFEST_DIR"));
        Robot::from_urdf_file(path).expect("shipped robot loads")
    }

    /// `count` rows of joint values, in the limits and up to a turn past them (a batch is not
    /// checked against the limits), from a fixed linear congruential sequence.
    fn configurations(robot: &Robot, count: usize) -> Vec<Real> {
        let mut state: u64 = 0x2545_f491_4f6c_dd1d;
        let mut unit = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 11) as Real / (1u64 << 53) as Real
        };
        let (lo, hi) = (robot.lower(), robot.upper());
        (0..count * DOF)
            .map(|i| {
                let k = i % DOF;
                let span = hi[k] - lo[k] + 4.0 * PI;
                lo[k] - 2.0 * PI + unit() * span
            })
            .collect()
    }

    fn joint_vector(row: &[Real]) -> crate::math::JointVector {
        crate::math::JointVector::from_column_slice(row)
    }

    /// The batched kernel multiplies in another order than `arm_pose` and takes its sines from
    /// other polynomials than the platform's: each differs by a few ulps, which over a chain
    /// of seven joints on an arm of about a metre stays far below 1e-12.
    const AGREEMENT: Real = 1e-12;

    fn largest_difference(a: &[Real], b: &[Real]) -> Real {
        assert_eq!(a.len(), b.len());
        a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, Real::max)
    }

    #[test]
    fn sines_and_cosines_agree_with_the_platform_to_an_ulp_or_two() {
        let mut worst: Real = 0.0;
        for i in -200_000..=200_000 {
            let x = i as Real * 2.5e-4 + 1e-7 * (i % 7) as Real;
            let (s, c) = reduced_sin_cos(&[x; LANES]);
            let (es, ec) = x.sin_cos();
            worst = worst.max((s[0] - es).abs()).max((c[0] - ec).abs());
        }
        assert!(worst <= 3.4e-16, "worst difference {worst:e}");
        // Past the reduction's range the platform's own, exactly.
        let far: Lane<LANES> = std::array::from_fn(|l| [3.0e5, -1.0e9, 0.5, 1e300][l % 4]);
        let (s, c) = sin_cos(&far);
        for l in 0..LANES {
            assert_eq!((s[l], c[l]), far[l].sin_cos());
        }
    }

    #[test]
    fn sines_keep_their_sign_at_the_quadrant_edges() {
        for j in -8..=8 {
            let x = j as Real * std::f64::consts::FRAC_PI_2;
            let (s, c) = reduced_sin_cos(&[x; LANES]);
            let (es, ec) = x.sin_cos();
            assert!((s[0] - es).abs() < 1e-15 && (c[0] - ec).abs() < 1e-15, "at {j} π/2");
        }
    }

    #[test]
    fn batched_frames_and_jacobians_match_the_per_configuration_functions() {
        for name in ROBOTS {
            let robot = robot(name);
            let chain = BatchedChain::new(&robot);
            let count = 4 * LANES + 3;
            let q = configurations(&robot, count);
            let (frames, jacobians) = frames_and_jacobians(&chain, &q);
            for (i, row) in q.chunks_exact(DOF).enumerate() {
                let pose = arm_pose(&robot, &joint_vector(row));
                let h = pose.hand_frame().to_homogeneous();
                let expected: Vec<Real> = (0..16).map(|v| h[(v / 4, v % 4)]).collect();
                let got = &frames[i * FRAME_VALUES..(i + 1) * FRAME_VALUES];
                let d = largest_difference(got, &expected);
                assert!(d < AGREEMENT, "{name} row {i}: frame differs by {d:e}");
                let j = geometric_jacobian(&pose);
                let expected: Vec<Real> =
                    (0..JACOBIAN_VALUES).map(|v| j[(v / DOF, v % DOF)]).collect();
                let got = &jacobians[i * JACOBIAN_VALUES..(i + 1) * JACOBIAN_VALUES];
                let d = largest_difference(got, &expected);
                assert!(d < AGREEMENT, "{name} row {i}: J_ge differs by {d:e}");
            }
        }
    }

    #[test]
    fn a_row_gets_the_same_bits_however_the_batch_is_split() {
        let robot = robot("iiwa14");
        let chain = BatchedChain::new(&robot);
        let count = 3 * LANES + 1;
        let q = configurations(&robot, count);
        let (frames, jacobians) = frames_and_jacobians(&chain, &q);
        let (mut alone_frames, mut alone_jacobians) = (frames.clone(), jacobians.clone());
        alone_frames.fill(0.0);
        alone_jacobians.fill(0.0);
        // Row by row, then from an odd offset in pieces of three.
        for (i, row) in q.chunks_exact(DOF).enumerate() {
            chain.hand_frames(row, &mut alone_frames[i * FRAME_VALUES..]);
            chain.jacobians(row, &mut alone_jacobians[i * JACOBIAN_VALUES..]);
        }
        assert_eq!(bits(&alone_frames), bits(&frames));
        assert_eq!(bits(&alone_jacobians), bits(&jacobians));
        let mut pieces = vec![0.0; count * FRAME_VALUES];
        chain.hand_frames(&q[..DOF], &mut pieces[..FRAME_VALUES]);
        for (p, rows) in q[DOF..].chunks(3 * DOF).enumerate() {
            let start = (1 + 3 * p) * FRAME_VALUES;
            chain.hand_frames(rows, &mut pieces[start..]);
        }
        assert_eq!(bits(&pieces), bits(&frames));
    }

    #[test]
    fn one_configuration_gets_the_bits_of_its_row_in_a_batch() {
        for name in ROBOTS {
            let robot = robot(name);
            let chain = BatchedChain::new(&robot);
            let count = 2 * LANES + 3;
            let q = configurations(&robot, count);
            let (frames, jacobians) = frames_and_jacobians(&chain, &q);
            for (row, q) in q.chunks_exact(DOF).enumerate() {
                let q: [Real; DOF] = std::array::from_fn(|k| q[k]);
                let (mut frame, mut jacobian) = ([0.0; FRAME_VALUES], [0.0; JACOBIAN_VALUES]);
                chain.hand_frame_and_jacobian(&q, &mut frame, &mut jacobian);
                let batch_frame = &frames[row * FRAME_VALUES..(row + 1) * FRAME_VALUES];
                let batch_jacobian = &jacobians[row * JACOBIAN_VALUES..(row + 1) * JACOBIAN_VALUES];
                assert_eq!(bits(&frame), bits(batch_frame), "{name} row {row}");
                assert_eq!(bits(&jacobian), bits(batch_jacobian), "{name} row {row}");
                let mut alone = [Real::NAN; FRAME_VALUES];
                chain.hand_frame(&q, &mut alone);
                assert_eq!(bits(&alone), bits(&frame), "{name} row {row}");
            }
        }
    }

    /// On a processor with AVX2 the public calls run the copy compiled for it: the same bits
    /// as the portable copy (on one without, both calls run the portable copy).
    #[test]
    fn the_avx2_copy_gives_the_portable_bits() {
        for name in ROBOTS {
            let robot = robot(name);
            let chain = BatchedChain::new(&robot);
            let count = 3 * LANES + 2;
            let q = configurations(&robot, count);
            let (frames, jacobians) = frames_and_jacobians(&chain, &q);
            let (mut portable_frames, mut portable_jacobians) =
                (vec![0.0; count * FRAME_VALUES], vec![0.0; count * JACOBIAN_VALUES]);
            let rows = portable_frames
                .chunks_exact_mut(FRAME_VALUES)
                .zip(portable_jacobians.chunks_exact_mut(JACOBIAN_VALUES));
            chain.each_group_portable::<true, false, _>(&q, rows, |pose, lane, (frame, j)| {
                write_frame(frame, pose, lane);
                write_jacobian(j, pose, lane);
            });
            assert_eq!(bits(&frames), bits(&portable_frames), "{name}");
            assert_eq!(bits(&jacobians), bits(&portable_jacobians), "{name}");
        }
    }

    #[test]
    fn signed_permutations_are_recognised_and_nothing_else() {
        let swap = [[0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [-1.0, 0.0, 0.0]];
        let expected = Constant::Permutation { source: [2, 0, 1], sign: [-1.0, -1.0, 1.0] };
        assert_eq!(Constant::of(&swap), expected);
        // A turn by π/2 in doubles: cos is 6.1e-17, within the snap.
        let (s, c) = std::f64::consts::FRAC_PI_2.sin_cos();
        let turn = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
        let expected = Constant::Permutation { source: [1, 0, 2], sign: [1.0, -1.0, 1.0] };
        assert_eq!(Constant::of(&turn), expected);
        // A URDF's 1.570796327 is 2e-10 off π/2: a general rotation.
        let (s, c) = (std::f64::consts::FRAC_PI_2 + 2e-10).sin_cos();
        let turn = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
        assert_eq!(Constant::of(&turn), Constant::General(turn));
        // Two columns from one row is no permutation.
        let twice = [[1.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 0.0]];
        assert_eq!(Constant::of(&twice), Constant::General(twice));
        assert_eq!(snapped([6e-17, 0.2, -3e-16]), [0.0, 0.2, 0.0]);
        assert_eq!(snapped([1e-3, 0.0, 0.0]), [1e-3, 0.0, 0.0]);
    }

    #[test]
    fn offsets_keep_their_nonzero_components_in_order() {
        assert_eq!(Offset::of([0.0, 0.0, 0.0]), Offset::Zero);
        assert_eq!(Offset::of([0.0, -0.2, 0.0]), Offset::One(1, -0.2));
        assert_eq!(Offset::of([0.1, 0.0, 0.3]), Offset::Two([(0, 0.1), (2, 0.3)]));
        assert_eq!(Offset::of([0.1, 0.2, 0.3]), Offset::Three([0.1, 0.2, 0.3]));
    }

    /// The signs folded into the sine and cosine give the bits of the product formed first.
    #[test]
    fn a_turned_permutation_gives_the_bits_of_the_formed_product() {
        let mut state: u64 = 7;
        let mut value = || {
            state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            (state >> 11) as Real / (1u64 << 53) as Real - 0.5
        };
        let m: LaneMatrix<LANES> =
            std::array::from_fn(|_| std::array::from_fn(|_| [(); LANES].map(|_| value())));
        let angles = [(); LANES].map(|_| 8.0 * value());
        let (sin, cos) = sin_cos(&angles);
        let permutations = [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]];
        let signs = [[1.0, 1.0, 1.0], [-1.0, 1.0, -1.0], [1.0, -1.0, -1.0]];
        for (source, sign) in permutations.into_iter().flat_map(|p| signs.map(|s| (p, s))) {
            let c = Constant::Permutation { source, sign };
            let expected = turned(&c.times(&m), &sin, &cos);
            let got = turned_permutation(&m, &source, &sign, &sin, &cos);
            let bits = |m: &LaneMatrix<LANES>| {
                m.as_flattened().as_flattened().iter().map(|v| v.to_bits()).collect::<Vec<_>>()
            };
            assert_eq!(bits(&got), bits(&expected), "{source:?} {sign:?}");
        }
    }

    /// The specialised products against the full ones: the same values (a zero's sign aside)
    /// where every snapped constant was exactly 0 or ±1 (the iiwa14's), else within rounding.
    #[test]
    fn the_specialised_chain_gives_the_full_products_values() {
        for name in ROBOTS {
            let robot = robot(name);
            let (fast, slow) = (BatchedChain::new(&robot), BatchedChain::general(&robot));
            let count = 3 * LANES + 1;
            let q = configurations(&robot, count);
            let (fast, slow) = (frames_and_jacobians(&fast, &q), frames_and_jacobians(&slow, &q));
            let d = largest_difference(&fast.0, &slow.0).max(largest_difference(&fast.1, &slow.1));
            assert!(d <= 1e-14, "{name}: {d:e}");
            if name == "iiwa14" {
                assert!(fast == slow, "{name}: the exact constants change a value");
            }
        }
    }

    /// The hand frames and J_ge of every row of `q` by the public call, into arrays of NaN (a
    /// row left unwritten stays NaN).
    fn frames_and_jacobians(chain: &BatchedChain, q: &[Real]) -> (Vec<Real>, Vec<Real>) {
        let count = q.len() / DOF;
        let mut frames = vec![Real::NAN; count * FRAME_VALUES];
        let mut jacobians = vec![Real::NAN; count * JACOBIAN_VALUES];
        chain.hand_frames_and_jacobians(q, &mut frames, &mut jacobians);
        (frames, jacobians)
    }

    fn bits(values: &[Real]) -> Vec<u64> {
        values.iter().map(|v| v.to_bits()).collect()
    }

    #[test]
    fn rows_pair_up_as_zip_does() {
        let robot = robot("panda");
        let chain = BatchedChain::new(&robot);
        let q = configurations(&robot, 6);
        // Two output rows for six configurations: two written, nothing past them.
        let mut frames = vec![Real::NAN; 2 * FRAME_VALUES + 5];
        chain.hand_frames(&q, &mut frames);
        assert!(frames[..2 * FRAME_VALUES].iter().all(|v| v.is_finite()));
        assert!(frames[2 * FRAME_VALUES..].iter().all(|v| v.is_nan()));
        // Six output rows for a configuration and a half: one written.
        let mut frames = vec![Real::NAN; 6 * FRAME_VALUES];
        chain.hand_frames(&q[..DOF + 3], &mut frames);
        assert!(frames[..FRAME_VALUES].iter().all(|v| v.is_finite()));
        assert!(frames[FRAME_VALUES..].iter().all(|v| v.is_nan()));
    }

    /// `cpsa_values` writes the bits `cpsa_states` gives, and stops at the first failing row.
    #[test]
    fn lane_atan2_is_within_a_few_ulps_of_the_platforms() {
        // Every quadrant, signed zeros, ratios from 1e-300 to 1e300 and each side of every
        // range boundary of the reduction.
        let mut values = vec![0.0, -0.0, 1e-300, 1e300, Real::INFINITY, Real::NAN];
        for boundary in [0.4375, 0.6875, 1.1875, 2.4375, 1.0] {
            for step in -3..=3 {
                values.push(boundary * (1.0 + Real::from(step) * 1e-15));
            }
        }
        let mut state: u64 = 0x9e37_79b9_7f4a_7c15;
        for _ in 0..4000 {
            state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            let unit = (state >> 11) as Real / (1u64 << 53) as Real;
            values.push(10.0_f64.powf(12.0 * unit - 6.0) * if state & 1 == 0 { 1.0 } else { 2.5 });
        }
        for (n, &y) in values.iter().enumerate() {
            let x = values[(n * 7 + 3) % values.len()];
            for (y, x) in [(y, x), (-y, x), (y, -x), (-y, -x), (x, y)] {
                let lanes = atan2(&[y; LANES], &[x; LANES]);
                let platform = y.atan2(x);
                for angle in lanes {
                    if platform.is_nan() {
                        assert!(angle.is_nan(), "atan2({y}, {x}) = {angle}, not NaN");
                        continue;
                    }
                    let ulps = (angle - platform).abs()
                        / (platform.abs().max(Real::MIN_POSITIVE) * Real::EPSILON);
                    assert!(ulps <= 4.0, "atan2({y}, {x}) = {angle}, the platform's {platform}");
                    assert_eq!(
                        angle.is_sign_negative(),
                        platform.is_sign_negative(),
                        "atan2({y}, {x})"
                    );
                }
            }
        }
    }

    #[test]
    fn cpsa_values_are_the_bits_of_cpsa_states() {
        let mut failures = 0;
        for name in ROBOTS {
            let robot = robot(name);
            let chain = BatchedChain::new(&robot);
            let rows = 3 * LANES + 2;
            let mut q = configurations(&robot, rows);
            let (mut pw, mut ow, mut swivel) =
                (vec![Real::NAN; 3 * rows], vec![Real::NAN; 9 * rows], vec![Real::NAN; rows]);
            assert!(chain.cpsa_values(&robot, &q, &mut pw, &mut ow, &mut swivel).is_none());
            let mut seen = 0;
            chain.cpsa_states(&robot, &q, |row, state| {
                let state = state.expect("regular rows");
                let ow_row: Vec<Real> = (0..9).map(|k| state.ow[(k / 3, k % 3)]).collect();
                assert_eq!(pw[3 * row..3 * row + 3], *state.pw.as_slice(), "{name} {row}");
                assert_eq!(ow[9 * row..9 * row + 9], ow_row[..], "{name} {row}");
                assert_eq!(swivel[row].to_bits(), state.swivel.to_bits(), "{name} {row}");
                seen += 1;
            });
            assert_eq!(seen, rows);
            // A straight arm (the zero configuration) in row LANES + 1: that row's error, the
            // rows before it written, none after.
            let bad = LANES + 1;
            q[DOF * bad..DOF * (bad + 1)].fill(0.0);
            let mut expected = None;
            chain.cpsa_states(&robot, &q, |row, state| {
                if let (None, Err(e)) = (&expected, state) {
                    expected = Some((row, e));
                }
            });
            let (mut pw, mut ow, mut swivel) =
                (vec![Real::NAN; 3 * rows], vec![Real::NAN; 9 * rows], vec![Real::NAN; rows]);
            let failed = chain.cpsa_values(&robot, &q, &mut pw, &mut ow, &mut swivel);
            assert_eq!(failed, expected, "{name}");
            // An arm whose zero configuration is not singular writes every row.
            let end = failed.as_ref().map_or(rows, |(row, _)| *row);
            failures += usize::from(failed.is_some());
            assert!(swivel[..end].iter().all(|v| v.is_finite()), "{name}");
            assert!(swivel[end..].iter().all(|v| v.is_nan()), "{name}");
            assert!(pw[3 * end..].iter().chain(&ow[9 * end..]).all(|v| v.is_nan()), "{name}");
        }
        assert!(failures > 0, "no arm was singular at its zero configuration");
    }

    #[test]
    fn batched_cpsa_states_match_cpsa_state_errors_included() {
        for name in ROBOTS {
            let robot = robot(name);
            let chain = BatchedChain::new(&robot);
            let mut q = configurations(&robot, 2 * LANES + 1);
            // The zero configuration of these arms is straight: a singular row.
            q[DOF..2 * DOF].fill(0.0);
            let mut seen = 0;
            chain.cpsa_states(&robot, &q, |row, state| {
                assert_eq!(row, seen);
                seen += 1;
                let pose = arm_pose(&robot, &joint_vector(&q[row * DOF..(row + 1) * DOF]));
                match (state, cpsa_state(&robot, &pose)) {
                    (Ok(got), Ok(expected)) => {
                        let d = (got.pw - expected.pw).amax();
                        let r = (got.ow.matrix() - expected.ow.matrix()).amax();
                        let s = crate::math::wrap_angle(got.swivel - expected.swivel).abs();
                        assert!(d.max(r).max(s) < 1e-10, "{name} row {row}: {d:e} {r:e} {s:e}");
                    }
                    (Err(got), Err(expected)) => assert_eq!(got, expected, "{name} row {row}"),
                    (got, expected) => panic!("{name} row {row}: {got:?} against {expected:?}"),
                }
            });
            assert_eq!(seen, 2 * LANES + 1);
        }
    }
}
