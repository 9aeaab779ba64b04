moreau::model! {
    pub struct A;
    coordinates { y: vy }
    kinetic = 0.5 * vy^2;
    potential = +y;
}

moreau::model! {
    pub struct C;
    coordinates { y: vy }
    kinetic = 0.5 * vy^2;
    potential = atan2(y);
}

moreau::model! {
    pub struct D;
    coordinates { y: vy }
    kinetic = 0.5 * vy^2;
    potential = [y];
}

moreau::model! {
    pub struct E;
    coordinates { y: vy }
    kinetic = 0.5 * vy^2;
    potential = ;
}

moreau::model! {
    pub struct F;
    coordinates { y: vy }
    kinetic = 0.5 * vy^2;
    potential = y y;
}

fn main() {}
